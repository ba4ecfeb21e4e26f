//! The sines and cosines of a sector BVH's node arcs ([`NodeArcs`]), made once for a structure
//! so that the ray traversals of its nodes take no trigonometry.

use rayon::prelude::*;

use super::{Bvh, SectorF32};
use crate::geometry::cylindrical::CylBounds;
use crate::geometry::pseudo_angle::{direction_of_pseudo, TURN};

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

/// [`arc_trig`] of every node of a cylindrical BVH, in node order.
///
/// ```
/// use cylvol::accel::bvh::{build_bvh, BvhParams, NodeArcs};
/// use cylvol::accel::space::Pieces;
/// use cylvol::geometry::cylindrical::{CylBounds, ThetaInterval};
/// let bounds: Vec<CylBounds> = (0..50)
///     .map(|i| CylBounds {
///         r: [1.0, 2.0],
///         theta: ThetaInterval::new(0.1 * i as f64 - 2.5, 0.1),
///         h: [0.0, 1.0],
///         straddles_axis: false,
///     })
///     .collect();
/// let bvh = build_bvh(&Pieces { bounds, cells: (0..50).collect() }, &BvhParams::default());
/// let arcs = NodeArcs::new(&bvh);
/// assert_eq!(arcs.trig().len(), bvh.stats().nodes);
/// assert_eq!(NodeArcs::new_sequential(&bvh).trig(), arcs.trig());
/// // Each is the sine and cosine of its node's arc ends.
/// for [s0, c0, s1, c1] in arcs.trig() {
///     assert!(((s0 * s0 + c0 * c0) - 1.0).abs() < 1e-12 && ((s1 * s1 + c1 * c1) - 1.0).abs() < 1e-12);
/// }
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NodeArcs {
    trig: Vec<ArcTrig>,
}

impl NodeArcs {
    /// The table of `bvh`'s nodes, made in parallel.
    pub fn new(bvh: &Bvh<CylBounds>) -> NodeArcs {
        NodeArcs {
            trig: bvh.nodes.par_iter().map(|n| arc_trig(&n.bounds)).collect(),
        }
    }

    /// [`NodeArcs::new`] on the calling thread only (for a table made lazily, whose maker
    /// must not wait on work the thread pool might hand back to it).
    pub fn new_sequential(bvh: &Bvh<CylBounds>) -> NodeArcs {
        NodeArcs {
            trig: bvh.nodes.iter().map(|n| arc_trig(&n.bounds)).collect(),
        }
    }

    /// The sines and cosines of each node's arc, in node order.
    pub fn trig(&self) -> &[ArcTrig] {
        &self.trig
    }
}
