//! Whether a point lies in a cell, and where: a padded bounding-box reject, the inverse map, and
//! a parametric acceptance test.
//!
//! # Tolerance and shared faces
//! A point is accepted when its parametric coordinates lie in
//! `[−CONTAINMENT_TOLERANCE, 1 + CONTAINMENT_TOLERANCE]³` with
//! [`CONTAINMENT_TOLERANCE`] `= 1e-9`.
//!
//! Why this closes every crack between neighbours: the face two conforming cells share is the
//! same bilinear patch in both (the trilinear map restricted to a face depends on that face's
//! four corners alone). A point on it therefore has, in exact arithmetic, the coordinate `1` in
//! one cell and `0` in the other (and the same in-range face coordinates in both); a point
//! beside it is on one side, so exactly inside one of the two cells. The computed coordinates
//! differ from the exact ones only by the inverse map's own rounding — it works relative to
//! corner 0, so the input is exact and the error is about `‖J⁻¹‖ · 1e-14 L`, i.e. `1e-14` times
//! the cell's condition number — far below `1e-9` for any cell up to a condition number of
//! 10⁴·⁵ or so. The point is thus accepted by at least one of the two cells.
//!
//! Why a point clearly outside is never accepted: an accepted result maps to the target within
//! `1e-10 L` (the inverse verifies it) from coordinates at most `1e-9` outside the cube, so the
//! point is within about `1e-9 · |J| ≲ 2e-9 L` of the cell.

use glam::DVec3;

use super::bounds::{cell_bounds, Aabb};
use super::inverse::{locate_within_hull, InverseStats};

/// Parametric slack of the acceptance test (see the module documentation).
pub const CONTAINMENT_TOLERANCE: f64 = 1e-9;

/// The padded box used for the quick reject: the cell's box enlarged by `4 · 1e-9` of its
/// diagonal (more than any accepted point can lie outside the cell) plus the rounding of the
/// coordinates' magnitude.
pub fn reject_box(corners: &[DVec3; 8]) -> Aabb {
    let b = cell_bounds(corners);
    let mag = b.min.abs().max(b.max.abs()).max_element();
    b.padded(4.0 * CONTAINMENT_TOLERANCE * b.diagonal() + 8.0 * f64::EPSILON * mag)
}

/// Whether parametric coordinates lie in the cell, to [`CONTAINMENT_TOLERANCE`].
#[inline]
pub fn param_inside(p: DVec3) -> bool {
    p.cmpge(DVec3::splat(-CONTAINMENT_TOLERANCE)).all()
        && p.cmple(DVec3::splat(1.0 + CONTAINMENT_TOLERANCE)).all()
}

/// The parametric coordinates of `p` in the cell if it lies in the cell (to the tolerance),
/// adding the inverse map's cost to `stats`. A point outside the padded box is rejected
/// before the inverse map, and (without a `guess`) one outside the corners' hull
/// ([`super::inverse::outside_hull`]) after Newton's first step
/// ([`super::inverse::locate_within_hull`]). `guess` seeds Newton (see
/// [`super::inverse::invert`]); Newton stops once the containment is settled
/// ([`super::inverse::PreparedCell::locate`]), so the coordinates are within about
/// [`super::inverse::LOCATE_STEP`] of the exact ones. The coordinates returned may lie up to
/// [`CONTAINMENT_TOLERANCE`] outside `[0, 1]³`; clamp them before interpolating if needed.
pub fn locate_in_cell_with_stats(
    corners: &[DVec3; 8],
    p: DVec3,
    guess: Option<DVec3>,
    stats: &mut InverseStats,
) -> Option<DVec3> {
    if !reject_box(corners).contains(p) {
        return None;
    }
    // Without a guess the point is often a structure's candidate outside the cell: the
    // corners' hull rejects most such points for the price of a few dot products, where the
    // inverse map of a point outside the cell may take many damped Newton steps; it is tested
    // once Newton's first steps leave the cell's parameter cube.
    let inv = locate_within_hull(corners, p, guess);
    *stats += inv.stats;
    inv.param().filter(|&q| param_inside(q))
}

/// The parametric coordinates of `p` in the cell if it lies in the cell (to the tolerance).
///
/// ```
/// use cylvol::geometry::containment::locate_in_cell;
/// use cylvol::geometry::trilinear::CORNER_PARAMETERS;
/// use glam::DVec3;
/// let cell = CORNER_PARAMETERS.map(|c| DVec3::from_array(c) * 2.0);
/// assert_eq!(locate_in_cell(&cell, DVec3::new(1.0, 0.5, 2.0), None), Some(DVec3::new(0.5, 0.25, 1.0)));
/// assert_eq!(locate_in_cell(&cell, DVec3::new(1.0, 0.5, 2.001), None), None);
/// ```
pub fn locate_in_cell(corners: &[DVec3; 8], p: DVec3, guess: Option<DVec3>) -> Option<DVec3> {
    let mut stats = InverseStats::default();
    locate_in_cell_with_stats(corners, p, guess, &mut stats)
}

/// Whether `p` lies in the cell (to the tolerance).
pub fn contains(corners: &[DVec3; 8], p: DVec3) -> bool {
    locate_in_cell(corners, p, None).is_some()
}

/// Whether `p` lies inside the cell for certain, by its face planes alone (no inverse map).
///
/// Each face is compared with its plane (through the face's centroid, normal to the cross
/// product of its diagonals, oriented away from the cell's centre): a bilinear face deviates
/// from that plane by at most `δ`, the largest distance of its corners from it (the distance
/// is bilinear on the face, so extreme at a corner). The region behind every face plane by
/// more than its `δ` (plus `1e-9` of the face's size) is convex, and meets no face, so it lies
/// wholly inside the cell or wholly outside; it is inside when it holds the cell's centre
/// `x(½, ½, ½)`, which is checked too. A `true` is therefore exact; a `false` says nothing
/// (twisted faces, points near a face, collapsed faces, and any non-finite input).
///
/// ```
/// use cylvol::geometry::containment::certainly_inside;
/// use cylvol::geometry::trilinear::CORNER_PARAMETERS;
/// use glam::DVec3;
/// let mut cell = CORNER_PARAMETERS.map(DVec3::from_array);
/// cell[6] += DVec3::new(0.1, 0.1, 0.1); // one face bent
/// assert!(certainly_inside(&cell, DVec3::splat(0.5)));
/// assert!(!certainly_inside(&cell, DVec3::new(0.5, 0.5, 1.2)));
/// // Inside (the bent face bulges to w ≈ 1.025 there) but too near that face to be sure.
/// assert!(cylvol::geometry::containment::contains(&cell, DVec3::new(0.5, 0.5, 1.01)));
/// assert!(!certainly_inside(&cell, DVec3::new(0.5, 0.5, 1.01)));
/// ```
pub fn certainly_inside(corners: &[DVec3; 8], p: DVec3) -> bool {
    use crate::mesh::topology::FACES;
    let x0 = corners[0];
    let rel = corners.map(|c| c - x0);
    let q = p - x0;
    let centre = rel.iter().fold(DVec3::ZERO, |a, &c| a + c) * 0.125;
    for slots in FACES {
        let face = slots.map(|s| rel[s]);
        let [a, b, c, e] = face;
        let mut n = (c - a).cross(e - b);
        let mid = (a + b + c + e) * 0.25;
        if n.dot(centre - mid) > 0.0 {
            n = -n;
        }
        let deviation = face
            .iter()
            .map(|&x| n.dot(x - mid).abs())
            .fold(0.0, f64::max);
        let size = (c - a).length().max((e - b).length());
        let limit = -deviation - 1e-9 * size * n.length();
        // Both the point and the centre strictly behind the shrunk plane (false on NaN).
        if !(n.dot(q - mid) < limit && n.dot(centre - mid) < limit) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::trilinear::{map, CORNER_PARAMETERS};

    fn cell() -> [DVec3; 8] {
        let mut c = CORNER_PARAMETERS.map(DVec3::from_array);
        c[6] += DVec3::new(0.3, 0.2, 0.25);
        c[3] += DVec3::new(-0.1, 0.1, 0.0);
        c
    }

    #[test]
    fn accepts_inside_rejects_outside() {
        let c = cell();
        for p in [
            DVec3::splat(0.5),
            DVec3::ZERO,
            DVec3::ONE,
            DVec3::new(0.0, 1.0, 0.3),
        ] {
            let x = map(&c, p);
            let q = locate_in_cell(&c, x, None).expect("inside");
            assert!((q - p).length() < 1e-12);
        }
        // Just outside each face along the outward parametric direction.
        for axis in 0..3 {
            for side in [0.0, 1.0] {
                let mut p = DVec3::splat(0.5);
                p[axis] = if side == 0.0 { -1e-6 } else { 1.0 + 1e-6 };
                assert!(!contains(&c, map(&c, p)), "axis {axis} side {side}");
            }
        }
        assert!(!contains(&c, DVec3::splat(50.0)));
        assert!(!contains(&c, DVec3::NAN));
    }

    #[test]
    fn collapsed_apex_is_inside() {
        let mut c = CORNER_PARAMETERS.map(DVec3::from_array);
        for ck in c.iter_mut().skip(4) {
            *ck = DVec3::new(0.3, 0.6, 1.2);
        }
        assert!(contains(&c, DVec3::new(0.3, 0.6, 1.2)));
        assert!(!contains(&c, DVec3::new(0.3, 0.6, 1.2 + 1e-6)));
        assert!(contains(&c, map(&c, DVec3::new(0.2, 0.9, 0.999))));
    }
}
