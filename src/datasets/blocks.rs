//! Building blocks shared by the synthetic datasets: grid-clustering functions, the choice of
//! integer block resolutions for a requested cell count, and the parallel assembly of a mesh
//! from per-index point and cell functions.
//!
//! Every dataset is a set of structured blocks whose points are numbered once (shared between
//! blocks by construction, never merged afterwards), so the assembly only has to evaluate
//! `point(index)` and `cell(index)` for every index: rayon fills the arrays by index, without
//! locks, and the result does not depend on the number of threads.

use glam::DVec3;
use rayon::prelude::*;

use crate::{CellKind, DataArray, Error, Mesh, MeshParts};

/// Grid fraction in `[0, 1]` for the uniform parameter `eta ∈ [0, 1]`, with points packed
/// towards `0` (a one-sided hyperbolic-tangent stretching of strength `beta`; `beta → 0` is
/// uniform). Exact at both ends.
pub(crate) fn cluster_start(eta: f64, beta: f64) -> f64 {
    if eta <= 0.0 {
        0.0
    } else if eta >= 1.0 {
        1.0
    } else if beta < 1e-6 {
        eta
    } else {
        1.0 + (beta * (eta - 1.0)).tanh() / beta.tanh()
    }
}

/// Like [`cluster_start`], packed towards `1`.
pub(crate) fn cluster_end(eta: f64, beta: f64) -> f64 {
    if eta <= 0.0 {
        0.0
    } else if eta >= 1.0 {
        1.0
    } else {
        1.0 - cluster_start(1.0 - eta, beta)
    }
}

/// Like [`cluster_start`], packed towards both ends symmetrically.
pub(crate) fn cluster_both(eta: f64, beta: f64) -> f64 {
    if eta <= 0.0 {
        0.0
    } else if eta >= 1.0 {
        1.0
    } else if beta < 1e-6 {
        eta
    } else {
        0.5 * (1.0 + (beta * (eta - 0.5)).tanh() / (0.5 * beta).tanh())
    }
}

/// Ken Perlin's smootherstep: 0 for `x ≤ 0`, 1 for `x ≥ 1`, C² in between.
pub(crate) fn smootherstep(x: f64) -> f64 {
    if x <= 0.0 {
        0.0
    } else if x >= 1.0 {
        1.0
    } else {
        x * x * x * (x * (6.0 * x - 15.0) + 10.0)
    }
}

/// How a dataset's three block resolutions scale with the requested cell count.
pub(crate) struct Resolution {
    /// The resolutions at scale 1; at scale `s` the ideal resolution is `weights · s`.
    pub weights: [f64; 3],
    /// Smallest allowed value of each resolution.
    pub min: [usize; 3],
    /// The first resolution must be a multiple of this (2 for the O-grid core).
    pub first_step: usize,
}

impl Resolution {
    /// The resolutions whose cell count `cells(dims)` is closest to `target`; `cells` must be
    /// a homogeneous cubic in the resolutions (e.g. `n(n + 4m)·l`, or `B·nr·nt·nz`).
    ///
    /// The scale `s = ∛(target / cells(weights))` gives ideal real resolutions; the first two
    /// are tried at the seven allowed integers nearest to their ideal, and for each pair the
    /// third is the integer nearest to `target ÷ (cells of one layer)`. Among the candidates
    /// within ±4 % of `target` (all, if none is) the one with the least cost wins (the first
    /// tried on a tie): the relative count error in units of 0.5 % plus the distance from the
    /// ideal shape (the sum of |ln(resolution / ideal)|), so large meshes land within a few
    /// hundredths of a percent and small ones keep a sensible shape. Deterministic and cheap (49 candidates).
    pub fn choose(&self, target: usize, cells: impl Fn([usize; 3]) -> usize) -> [usize; 3] {
        // The cell formulas are homogeneous cubics, so cells(weights · s) = s³ · cells(weights);
        // cells(weights) is evaluated exactly enough at 1000 × the weights.
        let k = 1000.0;
        let big = self.weights.map(|w| (w * k).round().max(1.0) as usize);
        let weight_cells = (cells(big) as f64 / (k * k * k)).max(1e-12);
        let s = (target as f64 / weight_cells).cbrt();
        let ideal = self.weights.map(|w| w * s);
        let step = self.first_step.max(1);
        // Seven candidates per resolution around the ideal, shifted up to respect the minimum.
        let first0 = self.min[0].div_ceil(step) * step;
        let centre0 = (ideal[0] / step as f64).round() as usize * step;
        let start0 = centre0.saturating_sub(3 * step).max(first0);
        let start1 = (ideal[1].round() as usize)
            .saturating_sub(3)
            .max(self.min[1]);
        let mut candidates: Vec<([usize; 3], usize, f64)> = Vec::with_capacity(49);
        for t0 in 0..7 {
            let d0 = start0 + t0 * step;
            for t1 in 0..7 {
                let d1 = start1 + t1;
                let layer = cells([d0, d1, 1]).max(1);
                let d2 = ((target as f64 / layer as f64).round() as usize).max(self.min[2]);
                let dims = [d0, d1, d2];
                let err = cells(dims).abs_diff(target);
                let dev: f64 = dims
                    .iter()
                    .zip(ideal)
                    .map(|(&d, i)| (d as f64 / i.max(1e-9)).ln().abs())
                    .sum();
                candidates.push((dims, err, dev));
            }
        }
        // Cost: relative count error in units of 0.5 %, plus the distance from the ideal
        // shape; candidates beyond ±4 % only if nothing is within.
        let cost = |c: &([usize; 3], usize, f64)| 200.0 * c.1 as f64 / target.max(1) as f64 + c.2;
        let within = |c: &([usize; 3], usize, f64)| c.1 * 25 <= target;
        let any_within = candidates.iter().any(within);
        candidates
            .into_iter()
            .filter(|c| within(c) || !any_within)
            .min_by(|a, b| cost(a).total_cmp(&cost(b)))
            .map_or(self.min, |c| c.0)
    }
}

/// What a dataset computes for one point: its position, `pressure` and `velocity`.
pub(crate) struct PointValue {
    /// Position.
    pub position: DVec3,
    /// The `pressure` scalar.
    pub pressure: f64,
    /// The `velocity` vector (Cartesian components).
    pub velocity: DVec3,
}

/// Builds and validates a hexahedral mesh whose point `i` is `point(i)` and whose cell `c` is
/// `cell(c)` (eight point indices, VTK hexahedron order). Arrays are filled in parallel by
/// index; the result is identical for any number of threads.
pub(crate) fn assemble<P, C>(
    n_points: usize,
    n_cells: usize,
    point: P,
    cell: C,
) -> Result<Mesh, Error>
where
    P: Fn(usize) -> PointValue + Sync,
    C: Fn(usize) -> [u32; 8] + Sync,
{
    if n_points > u32::MAX as usize {
        return Err(Error::Invalid(format!(
            "{n_points} points do not fit 32-bit point indices"
        )));
    }
    let mut points = vec![DVec3::ZERO; n_points];
    let mut pressure = vec![0.0; n_points];
    let mut velocity = vec![0.0; 3 * n_points];
    points
        .par_iter_mut()
        .zip(pressure.par_iter_mut())
        .zip(velocity.par_chunks_mut(3))
        .enumerate()
        .for_each(|(i, ((x, p), v))| {
            let value = point(i);
            *x = value.position;
            *p = value.pressure;
            v.copy_from_slice(&value.velocity.to_array());
        });
    let cells: Vec<[u32; 8]> = (0..n_cells).into_par_iter().map(&cell).collect();
    let kinds = vec![CellKind::Hexahedron; n_cells];
    Ok(Mesh::from_parts(MeshParts {
        points,
        cells,
        kinds,
        point_data: vec![
            DataArray::scalar("pressure", pressure),
            DataArray::vector("velocity", velocity),
        ],
        cell_data: Vec::new(),
    })?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clustering_is_monotone_exact_at_ends_and_packs_where_asked() {
        let fs: [fn(f64, f64) -> f64; 3] = [cluster_start, cluster_end, cluster_both];
        for f in fs {
            for beta in [0.0, 0.5, 2.0, 4.0] {
                assert_eq!(f(0.0, beta), 0.0);
                assert_eq!(f(1.0, beta), 1.0);
                let mut prev = 0.0;
                for i in 1..=100 {
                    let y = f(i as f64 / 100.0, beta);
                    assert!(y > prev, "not increasing at {i}");
                    prev = y;
                }
            }
        }
        let h = 0.01;
        let first = |f: fn(f64, f64) -> f64| f(h, 3.0) - f(0.0, 3.0);
        let last = |f: fn(f64, f64) -> f64| f(1.0, 3.0) - f(1.0 - h, 3.0);
        assert!(first(cluster_start) < h && last(cluster_start) > h);
        assert!(first(cluster_end) > h && last(cluster_end) < h);
        assert!(first(cluster_both) < h && last(cluster_both) < h);
        assert!((cluster_both(0.5, 3.0) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn smootherstep_is_flat_at_both_ends() {
        assert_eq!(smootherstep(-1.0), 0.0);
        assert_eq!(smootherstep(0.0), 0.0);
        assert_eq!(smootherstep(1.0), 1.0);
        assert_eq!(smootherstep(2.0), 1.0);
        assert!((smootherstep(0.5) - 0.5).abs() < 1e-12);
        assert!(smootherstep(1e-3) < 1e-8);
    }

    #[test]
    fn resolution_hits_the_target_and_respects_constraints() {
        let pipe = Resolution {
            weights: [1.0, 0.6, 2.0],
            min: [2, 1, 1],
            first_step: 2,
        };
        let cells = |[n, m, l]: [usize; 3]| n * (n + 4 * m) * l;
        for target in [1_000, 5_000, 77_777, 900_000, 12_345_678] {
            let d = pipe.choose(target, cells);
            assert_eq!(d[0] % 2, 0);
            let got = cells(d);
            assert!(
                got.abs_diff(target) * 20 <= target,
                "{target} → {got} {d:?}"
            );
            // Near the ideal shape (once the integers are fine enough): m ≈ 0.6 n, levels ≈ 2 n.
            if target < 50_000 {
                continue;
            }
            let n = d[0] as f64;
            assert!((d[1] as f64 / n - 0.6).abs() < 0.25, "{d:?}");
            assert!((d[2] as f64 / n - 2.0).abs() < 0.8, "{d:?}");
        }
    }
}
