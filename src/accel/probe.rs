//! Measuring point location: seeded points inside a mesh's cells, and the average work a
//! structure does to locate them — the talk's "hexahedra visited" and "internal / leaf nodes
//! visited", per lookup rather than per frame.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::{Accel, Counters};
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
    let elapsed = started.elapsed().as_secs_f64();
    let n = points.len().max(1) as f64;
    LookupCost {
        lookups: points.len(),
        found,
        hex_tests: counters.hex_tests as f64 / n,
        internal_visits: counters.internal_visits as f64 / n,
        leaf_visits: counters.leaf_visits as f64 / n,
        ns_per_lookup: elapsed * 1e9 / n,
    }
}
