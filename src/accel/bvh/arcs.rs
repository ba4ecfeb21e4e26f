//! The sines and cosines of a sector BVH's node arcs ([`NodeArcs`]), made once for a structure
//! so that the ray traversals of its nodes take no trigonometry.

use rayon::prelude::*;

use super::{Bvh, SectorF32};
use crate::geometry::cylindrical::CylBounds;
use crate::geometry::pseudo_angle::{angle_of_pseudo, TURN};

/// `[sin θ_lo, cos θ_lo, sin θ_hi, cos θ_hi]` of a sector's arc.
pub type ArcTrig = [f64; 4];

/// The sines and cosines of a sector's arc ends (stored as pseudo-angles).
#[inline]
pub fn arc_trig(s: &SectorF32) -> ArcTrig {
    let (s0, c0) = angle_of_pseudo(s.theta[0] as f64).sin_cos();
    let (s1, c1) = angle_of_pseudo(s.theta[1] as f64).sin_cos();
    [s0, c0, s1, c1]
}

/// Whether a stored sector's arc is narrower than `limit` radians (a whole turn is not).
/// The pseudo-angle rises by at least a half per radian, so an arc of pseudo-angles narrower
/// than half of `limit` is narrower than `limit`, which settles most arcs without
/// trigonometry; the others are measured.
///
/// ```
/// use cylvol::accel::bvh::{arc_narrower_than, SectorF32};
/// use cylvol::geometry::pseudo_angle::pseudo_of_angle;
/// let arc = |a: f64, b: f64| SectorF32 {
///     r: [1.0, 2.0],
///     theta: [pseudo_of_angle(a) as f32, pseudo_of_angle(b) as f32],
///     h: [0.0, 1.0],
/// };
/// assert!(arc_narrower_than(&arc(0.1, 0.3), 1.0));
/// assert!(arc_narrower_than(&arc(-3.0, 0.0), 3.1));
/// assert!(!arc_narrower_than(&arc(-3.0, 0.2), 3.1));
/// assert!(!arc_narrower_than(&arc(-3.2, 3.2), 3.1));
/// ```
#[inline]
pub fn arc_narrower_than(s: &SectorF32, limit: f64) -> bool {
    let (lo, hi) = (s.theta[0] as f64, s.theta[1] as f64);
    let span = hi - lo;
    if span < 0.5 * limit * (1.0 - 1e-9) {
        return true;
    }
    // NaN and whole turns are not narrow.
    if span >= TURN || span.is_nan() {
        return false;
    }
    angle_of_pseudo(hi) - angle_of_pseudo(lo) < limit
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
