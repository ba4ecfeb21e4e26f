//! The sort-based build: emit `(grid cell, id)` pairs in parallel, sort them, read off ranges.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::resolution::{lengths, resolution};
use super::{cell_of, inverse_size, linear, GridParams, Meta, TopCell, TwoLevelGrid};
use crate::accel::space::{Coordinates, Pieces};
use crate::geometry::bounds::Aabb;

/// Most top cells per axis.
const TOP_CAP: u32 = 1 << 12;
/// Most leaf cells per axis of one top cell (stored in a byte).
const LEAF_CAP: u32 = 255;
/// Most top cells in all.
const MAX_TOP_CELLS: u64 = 1 << 28;
/// Pieces (or top pairs) handed to one parallel task while emitting.
const CHUNK: usize = 4096;

/// Builds a two-level grid over boxes given in `coordinates` (for cylindrical coordinates,
/// `(r, θ, h)` boxes as [`crate::accel::space::linear_boxes`] makes them). Empty or non-finite
/// boxes are left out. Never panics; densities that would overflow the 32-bit ranges are
/// lowered until the grid fits.
///
/// ```
/// use cylvol::accel::grid::{build_grid, GridParams};
/// use cylvol::accel::{Coordinates, Counters, Pieces};
/// use cylvol::geometry::bounds::Aabb;
/// use glam::DVec3;
/// let pieces = Pieces {
///     bounds: vec![
///         Aabb::new(DVec3::ZERO, DVec3::ONE),
///         Aabb::new(DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 1.0)),
///     ],
///     cells: vec![7, 9],
/// };
/// let grid = build_grid(Coordinates::Cartesian, &pieces, &GridParams::default());
/// grid.assert_well_formed(&pieces);
/// let mut counters = Counters::default();
/// assert_eq!(grid.find(DVec3::new(1.5, 0.5, 0.5), &mut counters, |c| c == 9), Some(9));
/// assert_eq!(grid.find(DVec3::new(3.0, 0.5, 0.5), &mut counters, |_| true), None);
/// ```
pub fn build_grid(
    coordinates: Coordinates,
    pieces: &Pieces<Aabb>,
    params: &GridParams,
) -> TwoLevelGrid {
    let start = Instant::now();
    let cylindrical = matches!(coordinates, Coordinates::Cylindrical(_));
    let n = pieces
        .bounds
        .len()
        .min(pieces.cells.len())
        .min(u32::MAX as usize);
    let valid = |b: &Aabb| !b.is_empty() && b.min.is_finite() && b.max.is_finite();
    let (domain, count) = pieces.bounds[..n]
        .par_iter()
        .filter(|b| valid(b))
        .map(|b| (*b, 1usize))
        .reduce(|| (Aabb::EMPTY, 0), |a, b| (a.0.union(&b.0), a.1 + b.1));

    let mut top_density = params.top_density;
    let mut leaf_density = params.leaf_density;
    loop {
        let grid = attempt(
            coordinates,
            cylindrical,
            pieces,
            n,
            domain,
            count,
            top_density,
            leaf_density,
        );
        match grid {
            Some(mut g) => {
                g.meta.build_s = start.elapsed().as_secs_f64();
                return g;
            }
            // Too many leaf cells or references for 32-bit ranges: coarsen.
            None if leaf_density > 1e-6 => leaf_density /= 4.0,
            None => top_density /= 4.0,
        }
    }
}

/// One build at the given densities; `None` if the counts overflow 32 bits.
#[allow(clippy::too_many_arguments)]
fn attempt(
    coordinates: Coordinates,
    cylindrical: bool,
    pieces: &Pieces<Aabb>,
    n: usize,
    domain: Aabb,
    count: usize,
    top_density: f64,
    leaf_density: f64,
) -> Option<TwoLevelGrid> {
    let mut grid = TwoLevelGrid {
        meta: Box::new(Meta {
            coordinates,
            build_s: 0.0,
        }),
        domain,
        top_res: [1; 3],
        top_size: DVec3::ZERO,
        top_inv: DVec3::ZERO,
        top: Vec::new(),
        leaf_begin: vec![0],
        refs: Vec::new(),
    };
    if count == 0 || domain.is_empty() {
        grid.domain = Aabb::EMPTY;
        return Some(grid);
    }
    let extent = domain.extent();
    let inner_r = cylindrical.then_some(domain.min.x);
    let mut top_res = resolution(
        lengths(extent, inner_r),
        count as f64,
        top_density.max(0.0),
        TOP_CAP,
    );
    while top_res.iter().map(|&r| r as u64).product::<u64>() > MAX_TOP_CELLS {
        top_res = top_res.map(|r| (r / 2).max(1));
    }
    grid.top_res = top_res;
    grid.top_size = extent / DVec3::new(top_res[0] as f64, top_res[1] as f64, top_res[2] as f64);
    grid.top_inv = inverse_size(extent, top_res);
    let top_cells = top_res.iter().map(|&r| r as usize).product::<usize>();

    // Round one: (top cell, piece) pairs.
    let valid = |b: &Aabb| !b.is_empty() && b.min.is_finite() && b.max.is_finite();
    let top_range = |b: &Aabb| {
        (
            cell_of(b.min, domain.min, grid.top_inv, top_res),
            cell_of(b.max, domain.min, grid.top_inv, top_res),
        )
    };
    let mut top_pairs = emit(
        n,
        |i| {
            let b = &pieces.bounds[i];
            if !valid(b) {
                return 0;
            }
            let (lo, hi) = top_range(b);
            span(lo, hi)
        },
        |i, out| {
            let b = &pieces.bounds[i];
            if !valid(b) {
                return;
            }
            let (lo, hi) = top_range(b);
            let mut k = 0;
            for_each_cell(lo, hi, |c| {
                out[k] = (linear(c, top_res) as u64) << 32 | i as u64;
                k += 1;
            });
        },
    )?;
    top_pairs.par_sort_unstable();
    let top_begin = ranges(&top_pairs, top_cells);

    // Second-level resolution of every top cell, and where its leaf cells start.
    let mut top: Vec<TopCell> = (0..top_cells)
        .into_par_iter()
        .map(|t| {
            let n_t = top_begin[t + 1] - top_begin[t];
            if n_t == 0 {
                return TopCell::default();
            }
            let tc = grid.top_coords(t);
            let inner = inner_r.map(|_| domain.min.x + tc[0] as f64 * grid.top_size.x);
            let res = resolution(
                lengths(grid.top_size, inner),
                n_t as f64,
                leaf_density.max(0.0),
                LEAF_CAP,
            );
            TopCell {
                first: 0,
                res: res.map(|r| r as u8),
            }
        })
        .collect();
    let mut leaves: u64 = 0;
    for tc in &mut top {
        tc.first = u32::try_from(leaves).ok()?;
        leaves += tc.res.iter().map(|&r| r as u64).product::<u64>();
    }
    if leaves >= u32::MAX as u64 {
        return None;
    }
    grid.top = top;

    // Round two: (leaf cell, mesh cell) pairs, from every (top cell, piece) pair.
    let leaf_range = |pair: u64| {
        let t = (pair >> 32) as usize;
        let b = &pieces.bounds[(pair & 0xffff_ffff) as usize];
        let tc = grid.top[t];
        let (origin, inv) = grid.leaf_frame(grid.top_coords(t), tc.res);
        let res = tc.res.map(u32::from);
        (
            tc.first,
            res,
            cell_of(b.min, origin, inv, res),
            cell_of(b.max, origin, inv, res),
        )
    };
    let mut leaf_pairs = emit(
        top_pairs.len(),
        |k| {
            let (_, _, lo, hi) = leaf_range(top_pairs[k]);
            span(lo, hi)
        },
        |k, out| {
            let pair = top_pairs[k];
            let cell = pieces.cells[(pair & 0xffff_ffff) as usize] as u64;
            let (first, res, lo, hi) = leaf_range(pair);
            let mut j = 0;
            for_each_cell(lo, hi, |c| {
                out[j] = (first as u64 + linear(c, res) as u64) << 32 | cell;
                j += 1;
            });
        },
    )?;
    drop(top_pairs);
    leaf_pairs.par_sort_unstable();
    leaf_pairs.dedup();
    if leaf_pairs.len() >= u32::MAX as usize {
        return None;
    }
    let leaf_begin = ranges(&leaf_pairs, leaves as usize);
    grid.leaf_begin = leaf_begin.into_iter().map(|x| x as u32).collect();
    grid.refs = leaf_pairs.par_iter().map(|&p| p as u32).collect();
    Some(grid)
}

/// Number of cells in the inclusive index range `lo..=hi`.
fn span(lo: [u32; 3], hi: [u32; 3]) -> usize {
    (0..3)
        .map(|a| (hi[a].saturating_sub(lo[a]) + 1) as usize)
        .product()
}

/// Calls `f` on every cell of the inclusive index range, x fastest.
#[inline]
fn for_each_cell(lo: [u32; 3], hi: [u32; 3], mut f: impl FnMut([u32; 3])) {
    for z in lo[2]..=hi[2] {
        for y in lo[1]..=hi[1] {
            for x in lo[0]..=hi[0] {
                f([x, y, z]);
            }
        }
    }
}

/// Emits `count(i)` pairs for each of `n` items into one array, in item order: counts in
/// parallel, prefix sums, then each task fills its items' disjoint slice (no locks).
/// `None` if the total does not fit in memory indices.
fn emit(
    n: usize,
    count: impl Fn(usize) -> usize + Sync,
    fill: impl Fn(usize, &mut [u64]) + Sync,
) -> Option<Vec<u64>> {
    let counts: Vec<usize> = (0..n).into_par_iter().map(&count).collect();
    let mut offsets = Vec::with_capacity(n + 1);
    let mut total = 0usize;
    offsets.push(0);
    for c in counts {
        total = total.checked_add(c)?;
        offsets.push(total);
    }
    if total as u64 >= 1 << 36 {
        return None;
    }
    let mut out = vec![0u64; total];
    let mut slices = Vec::with_capacity(n.div_ceil(CHUNK));
    let mut rest: &mut [u64] = &mut out;
    for c in (0..n).step_by(CHUNK) {
        let end = (c + CHUNK).min(n);
        let (head, tail) = rest.split_at_mut(offsets[end] - offsets[c]);
        slices.push((c, end, head));
        rest = tail;
    }
    slices.into_par_iter().for_each(|(c, end, slice)| {
        let base = offsets[c];
        for i in c..end {
            fill(i, &mut slice[offsets[i] - base..offsets[i + 1] - base]);
        }
    });
    Some(out)
}

/// `[begin, end)` of each of `cells` cells in pairs sorted by their high 32 bits: `cells + 1`
/// starts, the last being `pairs.len()`.
fn ranges(pairs: &[u64], cells: usize) -> Vec<usize> {
    let mut begin = vec![0usize; cells + 1];
    for &p in pairs {
        begin[(p >> 32) as usize + 1] += 1;
    }
    for i in 0..cells {
        begin[i + 1] += begin[i];
    }
    begin
}
