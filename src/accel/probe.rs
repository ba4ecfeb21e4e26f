//! Measuring point location: seeded points inside a mesh's cells, and the average work a
//! structure does to locate them — the talk's "hexahedra visited" and "internal / leaf nodes
//! visited", per lookup rather than per frame ([`lookup_cost`]) — and the candidates it holds
//! a point to whatever their order ([`candidate_count`]).

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::{Accel, Counters};
use crate::geometry::containment::reject_box;
use crate::geometry::trilinear;
use crate::Mesh;

/// SplitMix64: a small, well-mixed, seedable generator (so sampling needs no extra crate).
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator from a seed.
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `n` points, each inside a cell chosen uniformly at random (the image of uniform parametric
/// coordinates), deterministic for a seed.
///
/// ```
/// let mesh = cylvol::datasets::generate(cylvol::datasets::Dataset::PumpRotor, 5_000).unwrap();
/// let a = cylvol::accel::probe::points_in_cells(&mesh, 10, 7);
/// assert_eq!(a, cylvol::accel::probe::points_in_cells(&mesh, 10, 7));
/// ```
pub fn points_in_cells(mesh: &Mesh, n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = SplitMix64::new(seed);
    (0..n)
        .map(|_| {
            let c = (rng.next_u64() % mesh.cell_count() as u64) as usize;
            let p = DVec3::new(rng.unit(), rng.unit(), rng.unit());
            trilinear::map(&mesh.cell_corners(c), p)
        })
        .collect()
}

/// The average work of locating points through a structure.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LookupCost {
    /// Points located.
    pub lookups: usize,
    /// Points for which a cell was found.
    pub found: usize,
    /// Cells tested per lookup.
    pub hex_tests: f64,
    /// Internal nodes (grids: top cells) visited per lookup.
    pub internal_visits: f64,
    /// Leaves (grids: second-level cells) visited per lookup.
    pub leaf_visits: f64,
    /// Wall time per lookup, in nanoseconds (all threads).
    pub ns_per_lookup: f64,
}

/// Locates every point through `accel` (in parallel) and averages the work.
pub fn lookup_cost(accel: &Accel, mesh: &Mesh, points: &[DVec3]) -> LookupCost {
    let started = Instant::now();
    let (counters, found) = points
        .par_iter()
        .fold(
            || (Counters::default(), 0usize),
            |(mut c, f), &p| {
                let hit = accel.locate(mesh, p, &mut c).is_some();
                (c, f + hit as usize)
            },
        )
        .reduce(
            || (Counters::default(), 0usize),
            |(mut a, fa), (b, fb)| {
                a += b;
                (a, fa + fb)
            },
        );
    average(&counters, found, points.len(), started)
}

/// [`lookup_cost`] on the calling thread only (for a measure made lazily, whose maker must
/// not wait on work the thread pool might hand back to it).
///
/// ```
/// use cylvol::accel::probe::{lookup_cost, lookup_cost_sequential, points_in_cells};
/// use cylvol::accel::{Accel, AccelParams, StructureKind};
/// let mesh = cylvol::datasets::generate(cylvol::datasets::Dataset::PumpRotor, 3_000).unwrap();
/// let axis = cylvol::axis::detect(&mesh);
/// let accel = Accel::build(&mesh, StructureKind::CartGrid, &axis, &AccelParams::default()).unwrap();
/// let points = points_in_cells(&mesh, 500, 3);
/// let (a, b) = (lookup_cost(&accel, &mesh, &points), lookup_cost_sequential(&accel, &mesh, &points));
/// assert_eq!((a.found, a.hex_tests, a.leaf_visits), (b.found, b.hex_tests, b.leaf_visits));
/// ```
pub fn lookup_cost_sequential(accel: &Accel, mesh: &Mesh, points: &[DVec3]) -> LookupCost {
    let started = Instant::now();
    let mut counters = Counters::default();
    let found = points
        .iter()
        .filter(|&&p| accel.locate(mesh, p, &mut counters).is_some())
        .count();
    average(&counters, found, points.len(), started)
}

/// The work of `lookups` look-ups, `found` of which found a cell, per look-up.
fn average(counters: &Counters, found: usize, lookups: usize, started: Instant) -> LookupCost {
    let elapsed = started.elapsed().as_secs_f64();
    let n = lookups.max(1) as f64;
    LookupCost {
        lookups,
        found,
        hex_tests: counters.hex_tests as f64 / n,
        internal_visits: counters.internal_visits as f64 / n,
        leaf_visits: counters.leaf_visits as f64 / n,
        ns_per_lookup: elapsed * 1e9 / n,
    }
}

/// The cells a structure holds points to, whatever their order ([`candidate_count`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CandidateCount {
    /// Points looked up.
    pub lookups: usize,
    /// Cells offered per lookup when the structure is made to offer all (none accepted): for
    /// a BVH, every cell with a piece whose bound holds the point (a cell cut at the axis may
    /// count once a piece); for a grid, every reference of the point's leaf cell. A lookup
    /// stops at the cell that holds the point, so the hexahedra it tests
    /// ([`LookupCost::hex_tests`]) are at most these and depend on the order they come in;
    /// these do not.
    pub candidates: f64,
    /// Of those, per lookup, the cells whose padded box ([`reject_box`]) holds the point too:
    /// those a test takes to the inverse map. The others are rejected by the box alone (a
    /// gather of eight corners and six comparisons), so these are what a structure's tighter
    /// bounds save of the costly part.
    pub in_box: f64,
}

/// Offers every point's candidates from `accel` (in parallel), accepting none, and averages
/// how many there are and how many of them have the point in their cell's padded box.
///
/// ```
/// use cylvol::accel::probe::{candidate_count, lookup_cost, points_in_cells};
/// use cylvol::accel::{Accel, AccelParams, StructureKind};
/// let mesh = cylvol::datasets::generate(cylvol::datasets::Dataset::PumpRotor, 5_000).unwrap();
/// let axis = cylvol::axis::detect(&mesh);
/// let accel = Accel::build(&mesh, StructureKind::CylBvh, &axis, &AccelParams::default()).unwrap();
/// let points = points_in_cells(&mesh, 1_000, 7);
/// let all = candidate_count(&accel, &mesh, &points);
/// let tested = lookup_cost(&accel, &mesh, &points).hex_tests;
/// // Every point is in a cell, whose box holds it; a lookup tests no more than all.
/// assert!(1.0 <= all.in_box && all.in_box <= all.candidates && tested <= all.candidates);
/// ```
pub fn candidate_count(accel: &Accel, mesh: &Mesh, points: &[DVec3]) -> CandidateCount {
    let (candidates, in_box) = points
        .par_iter()
        .map(|&p| {
            let (mut offered, mut boxed) = (0u64, 0u64);
            let q = accel.coordinates().query(p);
            accel.structure().find(q, &mut Counters::default(), |c| {
                offered += 1;
                boxed += u64::from(reject_box(&mesh.cell_corners(c as usize)).contains(p));
                false
            });
            (offered, boxed)
        })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    let n = points.len().max(1) as f64;
    CandidateCount {
        lookups: points.len(),
        candidates: candidates as f64 / n,
        in_box: in_box as f64 / n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{AccelParams, CandidateOrder, StructureKind};
    use crate::datasets::{generate, Dataset};

    /// The candidates do not depend on the order a structure offers them in (a grid's two
    /// candidate orders give the same counts, where the hexahedra a lookup tests differ); a
    /// lookup tests at most all of them; the Cartesian BVH's candidates are its padded boxes,
    /// so nearly all have the point in their cell's padded box; on a ring the sectors hold
    /// points to fewer candidates than the boxes, and fewer reach the inverse map.
    #[test]
    fn candidates_bound_the_tests_whatever_their_order() {
        let mesh = generate(Dataset::PumpRotor, 20_000).expect("rotor");
        let axis = crate::axis::detect(&mesh);
        let points = points_in_cells(&mesh, 4_000, 11);
        let build = |kind, order| {
            let mut params = AccelParams::default();
            params.grid.order = order;
            Accel::build(&mesh, kind, &axis, &params).expect("structure")
        };
        let mut counts = Vec::new();
        for kind in StructureKind::ALL {
            let by_cells = build(kind, CandidateOrder::Cells);
            let count = candidate_count(&by_cells, &mesh, &points);
            let tested = lookup_cost(&by_cells, &mesh, &points).hex_tests;
            assert!(tested <= count.candidates, "{kind:?}: {tested} > {count:?}");
            assert!(
                1.0 <= count.in_box && count.in_box <= count.candidates,
                "{kind:?}"
            );
            if kind.is_grid() {
                let by_share = build(kind, CandidateOrder::LargestShare);
                assert_eq!(
                    candidate_count(&by_share, &mesh, &points),
                    count,
                    "{kind:?}"
                );
                let share_tested = lookup_cost(&by_share, &mesh, &points).hex_tests;
                assert!(
                    share_tested < tested,
                    "{kind:?}: {share_tested} vs {tested}"
                );
            }
            counts.push((kind, count));
        }
        let get = |k| counts.iter().find(|(kind, _)| *kind == k).expect("kind").1;
        let (cart, cyl) = (get(StructureKind::CartBvh), get(StructureKind::CylBvh));
        assert!(cart.in_box >= 0.99 * cart.candidates, "{cart:?}");
        assert!(
            cyl.candidates < cart.candidates && cyl.in_box < cart.in_box,
            "{cyl:?} {cart:?}"
        );
    }
}
