//! Choosing between the Cartesian and the cylindrical family for a mesh by predicted cost: a
//! BVH's traversal cost grows with the surface area of its bounds, so compare the summed surface
//! area of the cylindrical pieces of a sample of cells with that of their boxes. Turbomachinery
//! cells hug sectors (ratio below 1); a Cartesian block's cells hug boxes (ratio above 1).

use crate::axis::Axis;
use crate::geometry::bounds::cell_bounds;
use crate::geometry::cylindrical::{straddle_sectors, CylFrame};
use crate::Mesh;

use super::space::DEFAULT_STRADDLE_SECTORS;
use super::StructureKind;

/// Cells sampled (evenly spaced through the mesh) for the prediction.
pub const SAMPLE_CELLS: usize = 8192;

/// Σ sector-piece surface area ÷ Σ box surface area over an even sample of cells, about
/// `axis`; `None` for an unusable axis or a mesh whose boxes have no area.
pub fn cylindrical_area_ratio(mesh: &Mesh, axis: &Axis) -> Option<f64> {
    let frame = CylFrame::new(axis.origin, axis.direction)?;
    let n = mesh.cell_count();
    let stride = n.div_ceil(SAMPLE_CELLS).max(1);
    let (mut cyl, mut cart) = (0.0, 0.0);
    for c in (0..n).step_by(stride) {
        let corners = mesh.cell_corners(c);
        cart += cell_bounds(&corners).surface_area();
        cyl += straddle_sectors(&corners, &frame, DEFAULT_STRADDLE_SECTORS)
            .iter()
            .map(|b| b.surface_area())
            .sum::<f64>();
    }
    (cart > 0.0 && cyl.is_finite()).then(|| cyl / cart)
}

/// The BVH of the family with the smaller predicted cost: cylindrical when its pieces' area is
/// below the boxes' ([`cylindrical_area_ratio`] < 1), else Cartesian.
///
/// ```
/// use cylvol::accel::{choose::auto_structure, StructureKind};
/// let rotor = cylvol::datasets::generate(cylvol::datasets::Dataset::PumpRotor, 5_000).unwrap();
/// let axis = cylvol::axis::detect(&rotor);
/// assert_eq!(auto_structure(&rotor, &axis), StructureKind::CylBvh);
/// ```
pub fn auto_structure(mesh: &Mesh, axis: &Axis) -> StructureKind {
    structure_for_ratio(cylindrical_area_ratio(mesh, axis))
}

/// The BVH a measured [`cylindrical_area_ratio`] calls for.
pub fn structure_for_ratio(ratio: Option<f64>) -> StructureKind {
    match ratio {
        Some(r) if r < 1.0 => StructureKind::CylBvh,
        _ => StructureKind::CartBvh,
    }
}
