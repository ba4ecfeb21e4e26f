//! How skipping rays test a sector BVH's nodes ([`NodeShapes`]), decided once for a
//! structure: a node whose box in the axis frame ([`sector_box`]) is at most
//! [`BOX_AREA_LIMIT`] times the sector's cross-section is tested as that box (slabs); any other
//! by its sector, with its arc's sines and cosines ([`arc_trig`]) made here so that the test
//! takes no trigonometry.
//!
//! A box test is a few products and comparisons; a sector's is a quadratic in `t` for each
//! radius (with square roots) and two half-planes through the axis (with divisions). On the
//! combustor's 18° sector every node's box is within twice its sector, and with the box tests
//! the cylindrical BVH's skipping costs what the Cartesian BVH's does; on a whole ring the
//! nodes near the root (wide arcs, or holes around the axis) keep their sectors, whose rays
//! the boxes would let in by the thousand.

use rayon::prelude::*;

use super::bounds::{f32_down, f32_up};
use super::{BoxF32, Bvh, SectorF32};
use crate::geometry::cylindrical::CylBounds;
use crate::geometry::pseudo_angle::{arc_width, direction_of_pseudo, TURN};

/// `[sin θ_lo, cos θ_lo, sin θ_hi, cos θ_hi]` of a sector's arc.
pub type ArcTrig = [f64; 4];

/// The sines and cosines of a sector's arc ends (stored as pseudo-angles), from their unit
/// vectors ([`direction_of_pseudo`]: no trigonometry, as this runs for every leaf piece a
/// skipping ray meets).
#[inline]
pub fn arc_trig(s: &SectorF32) -> ArcTrig {
    let (c0, s0) = direction_of_pseudo(s.theta[0] as f64);
    let (c1, s1) = direction_of_pseudo(s.theta[1] as f64);
    [s0, c0, s1, c1]
}

/// Whether a stored sector's arc is narrower than `π − 10⁻⁶`, where its two half-planes
/// through the axis bound it (`trig` its [`arc_trig`], if known). The pseudo-angle rises by
/// at least a half and at most one per radian, so an arc of pseudo-angles narrower than
/// `(π − 10⁻⁶)/2` is narrow, one of a whole turn is not, and any other is at least `π/2` and
/// less than `2π` wide: narrow exactly where the sine of its width is above `sin 10⁻⁶`.
///
/// ```
/// use cylvol::accel::bvh::{arc_narrower_than_half_turn, SectorF32};
/// use cylvol::geometry::pseudo_angle::pseudo_of_angle;
/// let arc = |a: f64, b: f64| SectorF32 {
///     r: [1.0, 2.0],
///     theta: [pseudo_of_angle(a) as f32, pseudo_of_angle(b) as f32],
///     h: [0.0, 1.0],
/// };
/// assert!(arc_narrower_than_half_turn(&arc(0.1, 0.3), None));
/// assert!(arc_narrower_than_half_turn(&arc(-3.0, 0.0), None));
/// assert!(!arc_narrower_than_half_turn(&arc(-3.0, 0.2), None));
/// assert!(!arc_narrower_than_half_turn(&arc(-3.2, 3.2), None));
/// ```
#[inline]
pub fn arc_narrower_than_half_turn(s: &SectorF32, trig: Option<&ArcTrig>) -> bool {
    const LIMIT: f64 = std::f64::consts::PI - 1e-6;
    let span = s.theta[1] as f64 - s.theta[0] as f64;
    if span < 0.5 * LIMIT {
        return true;
    }
    // NaN and whole turns are not narrow.
    if span >= TURN || span.is_nan() {
        return false;
    }
    let [s0, c0, s1, c1] = match trig {
        Some(t) => *t,
        None => arc_trig(s),
    };
    s1 * c0 - c1 * s0 > 1e-6f64.sin()
}

/// A node is tested as its box ([`sector_box`]) where the box's cross-section across the axis
/// is at most this many times the sector's: there the box lets in few more rays than the
/// sector, at a quarter of the test's cost. (The combustor's 18° sector, where every node is
/// within it: skipping rays' node visits 3.20 → 3.39 M a 512² frame; a whole ring of
/// `pump-rotor`: 0.87 → 0.94 M, its nodes near the root keeping their sectors, against 1.53 M
/// with boxes everywhere.)
pub const BOX_AREA_LIMIT: f64 = 2.0;

/// The box, in the axis frame, that holds a stored sector: `x` and `y` across the axis (the
/// frame's `e1`, `e2`), `h` as the sector stores it; rounded outward to `f32`. It is spanned
/// by the arc's ends on both circles and the outer circle's points at the quarter turns the arc
/// passes (the whole outer circle's square for a whole turn). An empty sector, or one with a
/// value that is not finite, gives the empty box (low above high).
///
/// ```
/// use cylvol::accel::bvh::{sector_box, SectorF32};
/// use cylvol::geometry::pseudo_angle::pseudo_of_angle;
/// use std::f64::consts::FRAC_PI_2;
/// // A quarter annulus of radii 1 to 2 from 0 to π/2: the box [0, 2] × [0, 2].
/// let s = SectorF32 {
///     r: [1.0, 2.0],
///     theta: [0.0, pseudo_of_angle(FRAC_PI_2) as f32],
///     h: [-1.0, 3.0],
/// };
/// let b = sector_box(&s);
/// assert!(b.min[0] <= 0.0 && b.min[0] > -1e-6 && b.max[0] >= 2.0 && b.max[0] < 2.0 + 1e-6);
/// assert!(b.min[1] <= 0.0 && b.min[1] > -1e-6 && b.max[1] >= 2.0 && b.max[1] < 2.0 + 1e-6);
/// assert_eq!((b.min[2], b.max[2]), (-1.0, 3.0));
/// ```
pub fn sector_box(s: &SectorF32) -> BoxF32 {
    let [r0, r1] = s.r.map(f64::from);
    let [t0, t1] = s.theta.map(f64::from);
    let finite =
        s.r.iter()
            .chain(&s.theta)
            .chain(&s.h)
            .all(|v| v.is_finite());
    if !(finite && 0.0 <= r0 && r0 <= r1 && t0 <= t1 && s.h[0] <= s.h[1]) {
        return BoxF32::EMPTY;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut take = |x: f64, y: f64| {
        lo = [lo[0].min(x), lo[1].min(y)];
        hi = [hi[0].max(x), hi[1].max(y)];
    };
    if t1 - t0 >= TURN {
        take(-r1, -r1);
        take(r1, r1);
    } else {
        for t in [t0, t1] {
            let (c, sn) = direction_of_pseudo(t);
            take(r0 * c, r0 * sn);
            take(r1 * c, r1 * sn);
        }
        // The quarter turns within the arc: pseudo-angles k = 0, 1, 2, 3 (mod a turn) point
        // along +x, +y, −x, −y.
        let mut k = t0.ceil();
        while k <= t1 {
            match (k as i64).rem_euclid(4) {
                0 => take(r1, 0.0),
                1 => take(0.0, r1),
                2 => take(-r1, 0.0),
                _ => take(0.0, -r1),
            }
            k += 1.0;
        }
    }
    // The unit vectors are correctly rounded within a few ulps: a margin far above that,
    // then outward to f32.
    let margin = 1e-12 * r1;
    let (down, up) = (|v: f64| f32_down(v - margin), |v: f64| f32_up(v + margin));
    BoxF32 {
        min: [down(lo[0]), down(lo[1]), s.h[0]],
        max: [up(hi[0]), up(hi[1]), s.h[1]],
    }
}

/// How a skipping ray tests one node of a sector BVH.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NodeShape {
    /// As its box in the axis frame ([`sector_box`]), by slabs.
    Box(BoxF32),
    /// As its sector, whose arc has these sines and cosines ([`arc_trig`]).
    Sector(ArcTrig),
}

impl NodeShape {
    /// The test for a node bounded by `s`: its box where that is at most [`BOX_AREA_LIMIT`]
    /// times the sector's cross-section (arc widths from
    /// [`arc_width`](crate::geometry::pseudo_angle::arc_width)), else its sector.
    ///
    /// ```
    /// use cylvol::accel::bvh::{NodeShape, SectorF32};
    /// use cylvol::geometry::pseudo_angle::pseudo_of_angle;
    /// let sector = |r0: f32, a: f64, b: f64| SectorF32 {
    ///     r: [r0, 2.0],
    ///     theta: [pseudo_of_angle(a) as f32, pseudo_of_angle(b) as f32],
    ///     h: [0.0, 1.0],
    /// };
    /// // A thin slice of a thick annulus along the x axis: nearly its box.
    /// assert!(matches!(NodeShape::of(&sector(1.0, -0.05, 0.05)), NodeShape::Box(_)));
    /// // The same slice turned by 45°: its box is twice as wide as it is.
    /// assert!(matches!(NodeShape::of(&sector(1.0, 0.74, 0.84)), NodeShape::Sector(_)));
    /// // Half a thin ring: its box is mostly empty.
    /// assert!(matches!(NodeShape::of(&sector(1.9, 0.1, 3.0)), NodeShape::Sector(_)));
    /// ```
    pub fn of(s: &SectorF32) -> NodeShape {
        let b = sector_box(s);
        let [r0, r1] = s.r.map(f64::from);
        let [t0, t1] = s.theta.map(f64::from);
        let sector_area = 0.5 * arc_width(t0, t1) * (r1 * r1 - r0 * r0);
        let box_area = (f64::from(b.max[0]) - f64::from(b.min[0]))
            * (f64::from(b.max[1]) - f64::from(b.min[1]));
        // (An empty box's area is −∞ or NaN, and its sector's test rejects every ray.)
        if box_area >= 0.0 && box_area <= BOX_AREA_LIMIT * sector_area {
            NodeShape::Box(b)
        } else {
            NodeShape::Sector(arc_trig(s))
        }
    }
}

/// [`NodeShape::of`] every node of a cylindrical BVH, in node order.
///
/// ```
/// use cylvol::accel::bvh::{build_bvh, BvhParams, NodeShape, NodeShapes};
/// use cylvol::accel::space::Pieces;
/// use cylvol::geometry::cylindrical::{CylBounds, ThetaInterval};
/// // A thin ring of 64 sectors.
/// let bounds: Vec<CylBounds> = (0..64)
///     .map(|i| CylBounds {
///         r: [1.5, 2.0],
///         theta: ThetaInterval::new(0.098 * i as f64 - 3.1, 0.1),
///         h: [0.0, 1.0],
///         straddles_axis: false,
///     })
///     .collect();
/// let bvh = build_bvh(&Pieces { bounds, cells: (0..64).collect() }, &BvhParams::FINE);
/// let tests = NodeShapes::new(&bvh);
/// assert_eq!(tests.all().len(), bvh.stats().nodes);
/// assert_eq!(NodeShapes::new_sequential(&bvh).all(), tests.all());
/// // The root spans the ring: its sector. Some short arcs are nearly their boxes.
/// assert!(matches!(tests.all()[0], NodeShape::Sector(_)));
/// assert!(tests.all().iter().any(|t| matches!(t, NodeShape::Box(_))));
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeShapes {
    tests: Vec<NodeShape>,
}

impl NodeShapes {
    /// The tests of `bvh`'s nodes, made in parallel.
    pub fn new(bvh: &Bvh<CylBounds>) -> NodeShapes {
        NodeShapes {
            tests: bvh
                .nodes
                .par_iter()
                .map(|n| NodeShape::of(&n.bounds))
                .collect(),
        }
    }

    /// [`NodeShapes::new`] on the calling thread only (for tests made lazily, whose maker
    /// must not wait on work the thread pool might hand back to it).
    pub fn new_sequential(bvh: &Bvh<CylBounds>) -> NodeShapes {
        NodeShapes {
            tests: bvh.nodes.iter().map(|n| NodeShape::of(&n.bounds)).collect(),
        }
    }

    /// Each node's test, in node order.
    pub fn all(&self) -> &[NodeShape] {
        &self.tests
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::pseudo_angle::angle_of_pseudo;
    use proptest::prelude::*;

    fn sector(r0: f64, dr: f64, lo: f64, width: f64) -> SectorF32 {
        SectorF32 {
            r: [r0 as f32, (r0 + dr) as f32],
            theta: [lo as f32, (lo + width) as f32],
            h: [-1.0, 2.5],
        }
    }

    proptest! {
        /// Every point of the sector lies in its box, and the box reaches no further than
        /// the sector's extreme points (the arc's ends on both circles, the outer circle's
        /// quarter turns) by more than its `f32` rounding: a lattice over the sector with
        /// those points, each from `sin_cos` of its angle (not the unit vectors the box is made
        /// from).
        #[test]
        fn a_sector_box_holds_its_sector_and_no_more(
            r0 in prop_oneof![Just(0.0), 0.0f64..5.0],
            dr in 0.0f64..5.0,
            lo in -2.0f64..6.0,
            width in prop_oneof![0.0f64..0.3, 0.0f64..4.5, Just(4.0), Just(0.0)],
        ) {
            let s = sector(r0, dr, lo, width);
            let b = sector_box(&s);
            let [r0, r1] = s.r.map(f64::from);
            let [t0, t1] = s.theta.map(f64::from);
            let mut phis: Vec<f64> = (0..=64).map(|i| t0 + (t1 - t0) * i as f64 / 64.0).collect();
            phis.extend((t0.ceil() as i64..=t1.floor() as i64).map(|k| k as f64));
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for phi in phis {
                let (sn, c) = angle_of_pseudo(phi).sin_cos();
                for j in 0..=8 {
                    let r = r0 + (r1 - r0) * j as f64 / 8.0;
                    let p = [r * c, r * sn];
                    for a in 0..2 {
                        prop_assert!(
                            b.min[a] as f64 <= p[a] && p[a] <= b.max[a] as f64,
                            "{p:?} outside {b:?} ({s:?})"
                        );
                        lo[a] = lo[a].min(p[a]);
                        hi[a] = hi[a].max(p[a]);
                    }
                }
            }
            let slack = 1e-6 * r1.max(1e-30);
            for a in 0..2 {
                prop_assert!(
                    lo[a] - b.min[a] as f64 <= slack && b.max[a] as f64 - hi[a] <= slack,
                    "{b:?} looser than [{lo:?}, {hi:?}] ({s:?})"
                );
            }
            prop_assert_eq!((b.min[2], b.max[2]), (s.h[0], s.h[1]));
        }

        /// A node is tested as its box exactly where the box's cross-section is at most
        /// `BOX_AREA_LIMIT` times the sector's.
        #[test]
        fn a_node_is_tested_as_its_box_where_that_is_nearly_as_tight(
            r0 in 0.0f64..5.0,
            dr in 0.01f64..5.0,
            lo in -2.0f64..6.0,
            width in prop_oneof![0.001f64..0.3, 0.0f64..4.5, Just(4.0)],
        ) {
            let s = sector(r0, dr, lo, width);
            let b = sector_box(&s);
            let [r0, r1] = s.r.map(f64::from);
            let [t0, t1] = s.theta.map(f64::from);
            // The sector's area from the angles' own difference (not `arc_width`).
            let w = (angle_of_pseudo(t1) - angle_of_pseudo(t0)).min(std::f64::consts::TAU);
            let ratio = (b.max[0] - b.min[0]) as f64 * (b.max[1] - b.min[1]) as f64
                / (0.5 * w * (r1 * r1 - r0 * r0));
            match NodeShape::of(&s) {
                NodeShape::Box(got) => {
                    prop_assert_eq!(got, b);
                    prop_assert!(ratio <= BOX_AREA_LIMIT * (1.0 + 1e-3), "{ratio}");
                }
                NodeShape::Sector(trig) => {
                    prop_assert_eq!(trig, arc_trig(&s));
                    prop_assert!(ratio >= BOX_AREA_LIMIT * (1.0 - 1e-3), "{ratio}");
                }
            }
        }
    }

    /// What `Accel::node_shapes` says a node's test holds with the structure.
    #[test]
    fn a_node_test_is_forty_bytes() {
        assert_eq!(std::mem::size_of::<NodeShape>(), 40);
    }

    #[test]
    fn an_empty_or_broken_sector_has_the_empty_box_and_its_sector_test() {
        let cases = [
            sector(2.0, -1.0, 0.0, 0.1),
            sector(1.0, 1.0, 0.5, -0.1),
            SectorF32 {
                r: [1.0, f32::NAN],
                theta: [0.0, 0.1],
                h: [0.0, 1.0],
            },
            SectorF32 {
                r: [1.0, 2.0],
                theta: [0.0, 0.1],
                h: [1.0, 0.0],
            },
        ];
        for s in cases {
            let b = sector_box(&s);
            assert!(b.min[0] > b.max[0], "{s:?}: {b:?}");
            assert!(matches!(NodeShape::of(&s), NodeShape::Sector(_)), "{s:?}");
        }
    }
}
