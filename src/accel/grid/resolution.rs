//! The density rules that size both levels of the grid.
//!
//! For `N` primitives in a region of volume `V`, a density `λ` asks for about `λN` grid cells
//! of roughly cubic shape: `R_i = L_i ∛(λN/V)` along each axis, where `L_i` is the region's
//! length along that axis (Kalojanov & Slusallek 2009). In Cartesian coordinates the lengths
//! are the extents `d_x, d_y, d_z`. In cylindrical ones a region `[r, r + d_r] × [θ, θ + d_θ]
//! × [h, h + d_h]` has the lengths `d_r`, the arc at mid radius `d_θ (2r + d_r)/2` and `d_h`,
//! and `V` is their product — exactly the region's volume `d_r d_θ (2r + d_r)/2 d_h`. The grid
//! is uniform in the pseudo-angle φ ([`crate::geometry::pseudo_angle`]), whose extent `d_φ`
//! stands for `d_θ = d_φ · π/2` on average over the turn (a turn is 4 in φ, `2π` in θ; a cell
//! of the grid spans between `d_φ` and `2 d_φ` radians, wider near the diagonals).
//!
//! The grid builds pass a region's lengths measured in its pieces instead
//! ([`shaped_lengths`]: `d_i / p_i` with `p_i` the pieces' mean extent), so that its cells are
//! shaped like the mean piece rather than cubic — in both coordinate systems.
//!
//! A region that is flat along some axis (length zero, or negligible beside the others) gets
//! one cell along it, and the rule is applied to the remaining axes with the matching power
//! (`(λN/A)^{1/2}` for an area `A`), so a planar mesh still gets a sensible grid.

use glam::DVec3;

/// Lengths at most this fraction of the longest one count as flat.
const FLAT: f64 = 1e-9;

/// The lengths of a region along each axis for the rule: its extents, or with `inner_r` (the
/// region's inner radius, in cylindrical coordinates `(r, φ, h)`) `(d_r, d_θ (2r + d_r)/2,
/// d_h)` with `d_θ = d_φ · π/2`.
pub(super) fn lengths(extent: DVec3, inner_r: Option<f64>) -> DVec3 {
    match inner_r {
        None => extent,
        Some(r) => DVec3::new(
            extent.x,
            extent.y * RADIANS_PER_PSEUDO * (2.0 * r.max(0.0) + extent.x) / 2.0,
            extent.z,
        ),
    }
}

/// The lengths of a region for the rule when its pieces' mean extent along each axis is known:
/// the region's extent measured in pieces, `d_i / p_i`. The rule then gives grid cells shaped
/// like the mean piece (`R_i ∝ d_i / p_i`) rather than cubes: a grid cell of sides `G_i` meets
/// about `Π (1 + G_i / p_i)` pieces of sides `p_i` laid side by side, which for a given number
/// of grid cells (a given `Π G_i`) is least when `G_i / p_i` is the same along every axis.
/// Cells of a turbomachine mesh follow its axis, radius and angle, so in cylindrical
/// coordinates the pieces' extents are as unequal as the cells' sides; a Cartesian grid is
/// shaped the same way.
///
/// Falls back to [`lengths`] where the mean extent is not positive and finite along every axis
/// the region is not flat along (a piece's extent below `1e-6` of its largest is raised to it).
pub(super) fn shaped_lengths(extent: DVec3, inner_r: Option<f64>, piece_extent: DVec3) -> DVec3 {
    let largest = piece_extent.max_element();
    if !(largest > 0.0 && largest.is_finite() && piece_extent.cmpge(DVec3::ZERO).all()) {
        return lengths(extent, inner_r);
    }
    extent / piece_extent.max(DVec3::splat(1e-6 * largest))
}

/// Radians per unit of pseudo-angle, on average over a turn.
const RADIANS_PER_PSEUDO: f64 = std::f64::consts::TAU / crate::geometry::pseudo_angle::TURN;

/// The resolution `R_i = L_i ∛(λN/V)` (rounded, at least 1, at most `cap` per axis) of a
/// region with the given lengths holding `count` primitives at density `density`.
pub(super) fn resolution(lengths: DVec3, count: f64, density: f64, cap: u32) -> [u32; 3] {
    let l = lengths.to_array();
    let longest = l.iter().copied().fold(0.0, f64::max);
    let want = density * count;
    let positive = |x: f64| x > 0.0 && x.is_finite();
    if !positive(longest) || !positive(want) {
        return [1; 3];
    }
    let live: Vec<f64> = l.iter().copied().filter(|&x| x > FLAT * longest).collect();
    let measure: f64 = live.iter().product();
    let k = (want / measure).powf(1.0 / live.len() as f64);
    l.map(|x| {
        if x > FLAT * longest {
            let r = (x * k).round();
            if r >= cap as f64 {
                cap
            } else if r >= 1.0 {
                r as u32
            } else {
                1
            }
        } else {
            1
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_gets_cubic_cells() {
        let r = resolution(DVec3::splat(2.0), 1000.0, 1.0, 1 << 20);
        assert_eq!(r, [10, 10, 10]);
        let r = resolution(DVec3::new(4.0, 2.0, 1.0), 8000.0, 1.0, 1 << 20);
        assert_eq!(r, [40, 20, 10]);
    }

    #[test]
    fn flat_and_empty_regions() {
        assert_eq!(resolution(DVec3::ZERO, 100.0, 1.0, 64), [1, 1, 1]);
        assert_eq!(resolution(DVec3::ONE, 0.0, 1.0, 64), [1, 1, 1]);
        assert_eq!(resolution(DVec3::ONE, f64::NAN, 1.0, 64), [1, 1, 1]);
        // A square: the rule in two dimensions.
        assert_eq!(
            resolution(DVec3::new(1.0, 1.0, 0.0), 100.0, 1.0, 64),
            [10, 10, 1]
        );
        assert_eq!(resolution(DVec3::splat(1.0), 1e12, 1.0, 64), [64, 64, 64]);
    }

    #[test]
    fn shaped_lengths_count_pieces_along_each_axis() {
        let l = shaped_lengths(DVec3::new(8.0, 2.0, 1.0), None, DVec3::new(4.0, 0.5, 0.25));
        assert_eq!(l, DVec3::new(2.0, 4.0, 4.0));
        // Pieces 8:1:1 in a cube of their length: cells 8:1:1 as well.
        let r = resolution(
            shaped_lengths(DVec3::splat(8.0), None, DVec3::new(8.0, 1.0, 1.0)),
            64.0,
            1.0,
            64,
        );
        assert_eq!(r, [1, 8, 8]);
        // Flat pieces along one axis are raised to 1e-6 of the largest extent.
        let l = shaped_lengths(DVec3::ONE, None, DVec3::new(1.0, 0.0, 1.0));
        assert_eq!(l, DVec3::new(1.0, 1e6, 1.0));
        // No usable mean extent: the region's plain lengths.
        for bad in [
            DVec3::ZERO,
            DVec3::splat(f64::NAN),
            DVec3::new(1.0, -1.0, 1.0),
        ] {
            let l = shaped_lengths(DVec3::new(2.0, 1.0, 2.0), Some(1.0), bad);
            assert_eq!(l, lengths(DVec3::new(2.0, 1.0, 2.0), Some(1.0)));
        }
    }

    #[test]
    fn cylindrical_lengths_use_mid_radius_arc() {
        // Annulus r ∈ [1, 3], a quarter turn (1 in pseudo-angle), height 2: arc at r = 2 is π.
        let l = lengths(DVec3::new(2.0, 1.0, 2.0), Some(1.0));
        assert!((l.y - std::f64::consts::PI).abs() < 1e-15);
        // The product is the sector's volume: (r1² − r0²)/2 · dθ · dh = 4 · π/2 · 2.
        let v = l.x * l.y * l.z;
        assert!((v - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    }
}
