//! The sort-based build: emit `(grid cell, id)` pairs in parallel, sort them, read off ranges.

use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::resolution::{resolution, shaped_lengths};
use super::{
    cell_of, inverse_size, linear, CandidateOrder, GridParams, Meta, TopCell, TwoLevelGrid,
};
use crate::accel::space::{Coordinates, Pieces};
use crate::geometry::bounds::Aabb;

/// Most top cells per axis.
const TOP_CAP: u32 = 1 << 12;
/// Most leaf cells per axis of one top cell (stored in a byte).
const LEAF_CAP: u32 = 255;
/// Most top cells in all.
const MAX_TOP_CELLS: u64 = 1 << 28;
/// Most top cells per piece, beyond [`TOP_CELLS_FLOOR`].
const TOP_CELLS_PER_PIECE: u64 = 16;
/// Top cells any grid may have, whatever its pieces.
const TOP_CELLS_FLOOR: u64 = 1 << 12;
/// Most leaf cells per piece, beyond [`LEAF_CELLS_FLOOR`].
const LEAF_CELLS_PER_PIECE: u64 = 64;
/// Leaf cells any grid may have, whatever its pieces.
const LEAF_CELLS_FLOOR: u64 = 1 << 16;
/// Most references (piece–grid cell pairs) per piece at either level, beyond [`REFS_FLOOR`].
const REFS_PER_PIECE: u64 = 512;
/// References any grid may have at either level, whatever its pieces.
const REFS_FLOOR: u64 = 1 << 20;
/// Fewest pieces handed to one parallel task in round one.
const CHUNK: usize = 4096;
/// Most per-chunk top-cell counters in round one (they limit the number of chunks).
const HISTOGRAM_BUDGET: usize = 1 << 24;

/// Builds a two-level grid over boxes given in `coordinates` (for cylindrical coordinates,
/// `(r, φ, h)` boxes as [`crate::accel::space::linear_boxes`] makes them). Empty or non-finite
/// boxes are left out. Never panics; densities that would overflow the 32-bit ranges, or the
/// grid's memory budget, are lowered until the grid fits. The budget, per piece: 16 top cells,
/// 64 leaf cells and 512 references at each level (a few thousand cells and a million
/// references whatever the pieces); the presets stay well within it (`fast` on the 300 k
/// pump rotor: 0.26 top cells, 14 leaf cells and 158 references a piece), so only densities
/// far beyond them are lowered.
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
    let Totals {
        domain,
        count,
        extents,
        weights,
    } = totals(&pieces.bounds[..n], cylindrical);
    let piece_extent = extents / weights;

    let mut top_density = params.top_density;
    let mut leaf_density = params.leaf_density;
    loop {
        let grid = attempt(
            coordinates,
            pieces,
            n,
            domain,
            (count, piece_extent),
            (top_density, leaf_density),
            params.order,
        );
        match grid {
            Ok(mut g) => {
                g.meta.build_s = start.elapsed().as_secs_f64();
                return g;
            }
            // Too many cells or references at one level: coarsen that level (the second
            // level down to one leaf cell per top cell, then the top level).
            Err(Overflow::Leaves) if leaf_density > 1e-6 => leaf_density /= 4.0,
            Err(_) => top_density /= 4.0,
        }
    }
}

/// What the build needs of all valid pieces together.
#[derive(Clone, Copy)]
struct Totals {
    /// The union of their boxes.
    domain: Aabb,
    /// How many there are.
    count: usize,
    /// The sum of their extents, each times its [`volume_weight`].
    extents: DVec3,
    /// The sum of their weights.
    weights: f64,
}

impl Totals {
    const NONE: Totals = Totals {
        domain: Aabb::EMPTY,
        count: 0,
        extents: DVec3::ZERO,
        weights: 0.0,
    };

    fn add(self, other: Totals) -> Totals {
        Totals {
            domain: self.domain.union(&other.domain),
            count: self.count + other.count,
            extents: self.extents + other.extents,
            weights: self.weights + other.weights,
        }
    }
}

/// The [`Totals`] of the valid boxes among `bounds`, the same bits whatever the threads: the
/// boxes are summed in chunks of a fixed size in parallel, each chunk in order, and the
/// chunks' sums in order (a parallel reduction would round differently as the work is split,
/// and the grid's resolution, a floor of these sums, could change from one run to the next).
fn totals(bounds: &[Aabb], cylindrical: bool) -> Totals {
    let valid = |b: &Aabb| !b.is_empty() && b.min.is_finite() && b.max.is_finite();
    bounds
        .par_chunks(CHUNK)
        .map(|chunk| {
            chunk
                .iter()
                .filter(|b| valid(b))
                .fold(Totals::NONE, |sum, b| {
                    let w = volume_weight(b, cylindrical);
                    sum.add(Totals {
                        domain: *b,
                        count: 1,
                        extents: b.extent() * w,
                        weights: w,
                    })
                })
        })
        .collect::<Vec<Totals>>()
        .into_iter()
        .fold(Totals::NONE, Totals::add)
}

/// The weight of a piece in its region's mean extent: the share of the region's volume its
/// queries come from. In cylindrical coordinates `(r, φ, h)` a box at radius `r` holds `r`
/// times the volume of the same box at radius 1, so it weighs its mid-radius (the pieces near
/// the axis, which span wide angles, hold little volume); in Cartesian ones every piece
/// weighs 1.
fn volume_weight(b: &Aabb, cylindrical: bool) -> f64 {
    if cylindrical {
        0.5 * (b.min.x + b.max.x).max(0.0)
    } else {
        1.0
    }
}

/// Which level of a build at given densities went over its budget (or 32 bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Overflow {
    /// The top cells' references.
    Top,
    /// The leaf cells or their references.
    Leaves,
}

/// The budget of a grid over `count` pieces: `per_piece` a piece beyond `floor`.
fn budget(count: usize, per_piece: u64, floor: u64) -> u64 {
    (count as u64)
        .saturating_mul(per_piece)
        .saturating_add(floor)
}

/// One build at the given densities; which level overflowed when one does.
fn attempt(
    coordinates: Coordinates,
    pieces: &Pieces<Aabb>,
    n: usize,
    domain: Aabb,
    (count, piece_extent): (usize, DVec3),
    (top_density, leaf_density): (f64, f64),
    order: CandidateOrder,
) -> Result<TwoLevelGrid, Overflow> {
    let cylindrical = matches!(coordinates, Coordinates::Cylindrical(_));
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
        return Ok(grid);
    }
    let extent = domain.extent();
    let inner_r = cylindrical.then_some(domain.min.x);
    let mut top_res = resolution(
        shaped_lengths(extent, inner_r, piece_extent),
        count as f64,
        top_density.max(0.0),
        TOP_CAP,
    );
    let most_top_cells = MAX_TOP_CELLS.min(budget(count, TOP_CELLS_PER_PIECE, TOP_CELLS_FLOOR));
    while top_res.iter().map(|&r| r as u64).product::<u64>() > most_top_cells {
        top_res = top_res.map(|r| (r / 2).max(1));
    }
    grid.top_res = top_res;
    grid.top_size = extent / DVec3::new(top_res[0] as f64, top_res[1] as f64, top_res[2] as f64);
    grid.top_inv = inverse_size(extent, top_res);
    let top_cells = top_res.iter().map(|&r| r as usize).product::<usize>();

    // References allowed at each level.
    let most_refs = budget(count, REFS_PER_PIECE, REFS_FLOOR);

    // Round one: the pieces of every top cell, in piece order (a stable counting sort).
    let valid = |b: &Aabb| !b.is_empty() && b.min.is_finite() && b.max.is_finite();
    let top_inv = grid.top_inv;
    let (top_begin, top_refs) = group_by_top_cell(
        n,
        top_cells,
        |i| {
            let b = &pieces.bounds[i];
            valid(b).then(|| {
                (
                    cell_of(b.min, domain.min, top_inv, top_res),
                    cell_of(b.max, domain.min, top_inv, top_res),
                )
            })
        },
        top_res,
        most_refs,
    )
    .ok_or(Overflow::Top)?;

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
            // The mean extent of its pieces, each clipped to the top cell's size.
            let (sum, weights) = top_refs[top_begin[t]..top_begin[t + 1]].iter().fold(
                (DVec3::ZERO, 0.0),
                |(sum, weights), &i| {
                    let b = &pieces.bounds[i as usize];
                    let w = volume_weight(b, cylindrical);
                    (sum + b.extent().min(grid.top_size) * w, weights + w)
                },
            );
            let mean = sum / weights;
            let res = resolution(
                shaped_lengths(grid.top_size, inner, mean),
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
        tc.first = u32::try_from(leaves).map_err(|_| Overflow::Leaves)?;
        leaves += tc.res.iter().map(|&r| r as u64).product::<u64>();
    }
    if leaves >= u32::MAX as u64 || leaves > budget(count, LEAF_CELLS_PER_PIECE, LEAF_CELLS_FLOOR) {
        return Err(Overflow::Leaves);
    }
    grid.top = top;
    let (refs, leaf_begin) = fill_leaves(&grid, pieces, (&top_begin, &top_refs), most_refs, order)
        .ok_or(Overflow::Leaves)?;
    drop(top_refs);
    grid.leaf_begin = leaf_begin;
    grid.refs = refs;
    Ok(grid)
}

/// The leaf cells a top cell's piece overlaps: `(lo, hi)` inclusive, in the top cell's second
/// level of resolution `res` with origin and inverse cell size `frame`.
#[inline]
fn leaf_range(b: &Aabb, (origin, inv): (DVec3, DVec3), res: [u32; 3]) -> ([u32; 3], [u32; 3]) {
    (
        cell_of(b.min, origin, inv, res),
        cell_of(b.max, origin, inv, res),
    )
}

/// Round two, top cell by top cell in parallel (a top cell's leaf cells and their references
/// are contiguous, so every top cell fills its own slices): counts the references of each leaf
/// cell, then writes the cell ids of each leaf cell's pieces without duplicates (a cell
/// reaching one leaf cell through two pieces is kept once) in `order`, and packs the result.
/// Returns the references and the leaf cells' starts; `None` if they overflow 32 bits or
/// number more than `most_refs` (then the counting stops early).
fn fill_leaves(
    grid: &TwoLevelGrid,
    pieces: &Pieces<Aabb>,
    (top_begin, top_refs): (&[usize], &[u32]),
    most_refs: u64,
    order: CandidateOrder,
) -> Option<(Vec<u32>, Vec<u32>)> {
    let top = &grid.top;
    let leaves = top
        .last()
        .map_or(0, |tc| tc.first as usize + leaf_count(tc.res));
    // What a top cell's task needs: its index, its leaf frame and resolution, its pieces.
    let task = |t: usize| {
        let tc = top[t];
        let res = tc.res.map(u32::from);
        let frame = grid.leaf_frame(grid.top_coords(t), tc.res);
        (res, frame, &top_refs[top_begin[t]..top_begin[t + 1]])
    };

    // Counts per leaf cell; a top cell whose own count goes over the budget stops the build.
    let mut counts = vec![0usize; leaves];
    split_by_top_cell(top, &mut counts, |t| leaf_count(top[t].res))
        .into_par_iter()
        .try_for_each(|(t, counts)| {
            let (res, frame, mine) = task(t);
            let mut pairs = 0u64;
            for &i in mine {
                let (lo, hi) = leaf_range(&pieces.bounds[i as usize], frame, res);
                pairs += range_size(lo, hi);
                if pairs > most_refs {
                    return None;
                }
                for_each_cell(lo, hi, |c| counts[linear(c, res)] += 1);
            }
            Some(())
        })?;
    let mut begin = Vec::with_capacity(leaves + 1);
    let mut total = 0usize;
    begin.push(0);
    for &c in &counts {
        total = total.checked_add(c)?;
        begin.push(total);
    }
    if total as u64 >= 1 << 36 || total as u64 > most_refs {
        return None;
    }

    // References per top cell, each leaf cell's deduplicated and ordered at the front of its
    // top cell's slice; `counts` becomes the number kept per leaf cell, `kept` per top cell.
    let mut refs = vec![0u32; total];
    let slices = {
        let mut rest: &mut [u32] = &mut refs;
        let mut out = Vec::with_capacity(top.len());
        for (t, tc) in top.iter().enumerate() {
            let (a, b) = (tc.first as usize, tc.first as usize + leaf_count(tc.res));
            let (head, tail) = rest.split_at_mut(begin[b] - begin[a]);
            out.push((t, head));
            rest = tail;
        }
        out
    };
    let kept: Vec<usize> = slices
        .into_par_iter()
        .zip(split_by_top_cell(top, &mut counts, |t| {
            leaf_count(top[t].res)
        }))
        .map(|((t, out), (_, counts))| {
            let (res, frame, mine) = task(t);
            let first = top[t].first as usize;
            let base = begin[first];
            let mut cursor: Vec<usize> = begin[first..first + counts.len()]
                .iter()
                .map(|&b| b - base)
                .collect();
            // Each reference's share of its leaf cell, beside it (for that order only).
            let by_share = order == CandidateOrder::LargestShare;
            let leaf_size = grid.top_size / DVec3::new(res[0] as f64, res[1] as f64, res[2] as f64);
            let mut share = vec![0f32; if by_share { out.len() } else { 0 }];
            for &i in mine {
                let cell = pieces.cells[i as usize];
                let b = &pieces.bounds[i as usize];
                let (lo, hi) = leaf_range(b, frame, res);
                for_each_cell(lo, hi, |c| {
                    let k = &mut cursor[linear(c, res)];
                    out[*k] = cell;
                    if by_share {
                        share[*k] = overlap_share(b, frame.0, leaf_size, c);
                    }
                    *k += 1;
                });
            }
            // Per leaf cell: one reference a cell (with its largest share), in order, packed to
            // the front of the top cell's slice.
            let mut pairs: Vec<(u32, f32)> = Vec::new();
            let mut w = 0;
            for (j, count) in counts.iter_mut().enumerate() {
                let (s, e) = (begin[first + j] - base, begin[first + j + 1] - base);
                let w0 = w;
                if by_share {
                    pairs.clear();
                    pairs.extend(out[s..e].iter().copied().zip(share[s..e].iter().copied()));
                    // Pieces usually come in cell order, one a cell: nothing to drop then.
                    if !pairs.windows(2).all(|p| p[0].0 < p[1].0) {
                        pairs.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
                        pairs.dedup_by_key(|p| p.0);
                    }
                    pairs.sort_unstable_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
                    for p in &pairs {
                        out[w] = p.0;
                        w += 1;
                    }
                } else {
                    // Sort (pieces come in piece order, usually already in cell order), drop
                    // repeats.
                    let seg = &mut out[s..e];
                    if !seg.windows(2).all(|p| p[0] <= p[1]) {
                        seg.sort_unstable();
                    }
                    for k in s..e {
                        if k == s || out[k] != out[k - 1] {
                            out[w] = out[k];
                            w += 1;
                        }
                    }
                }
                *count = w - w0;
            }
            w
        })
        .collect();

    // Pack the top cells' slices (only where duplicates were dropped).
    let kept_total: usize = kept.iter().sum();
    if kept_total >= u32::MAX as usize {
        return None;
    }
    if kept_total < total {
        let mut w = 0;
        for (tc, &k) in top.iter().zip(&kept) {
            let s = begin[tc.first as usize];
            refs.copy_within(s..s + k, w);
            w += k;
        }
        refs.truncate(w);
        refs.shrink_to_fit();
    }
    let mut leaf_begin = Vec::with_capacity(leaves + 1);
    let mut acc = 0u32;
    leaf_begin.push(0);
    for &c in &counts {
        acc += c as u32;
        leaf_begin.push(acc);
    }
    Some((refs, leaf_begin))
}

/// Leaf cells of a top cell of second-level resolution `res`.
fn leaf_count(res: [u8; 3]) -> usize {
    res.iter().map(|&r| r as usize).product()
}

/// `data` (one entry per leaf cell) cut into each top cell's slice, with the top cell's index.
fn split_by_top_cell<'a, T>(
    top: &[TopCell],
    data: &'a mut [T],
    len: impl Fn(usize) -> usize,
) -> Vec<(usize, &'a mut [T])> {
    let mut rest = data;
    let mut out = Vec::with_capacity(top.len());
    for t in 0..top.len() {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len(t));
        out.push((t, head));
        rest = tail;
    }
    out
}

/// Round one: the pieces overlapping each top cell, as `top_cells + 1` starts and the piece
/// indices, in piece order within each top cell — what sorting the `(top cell, piece)` pairs
/// would give. A stable counting sort: chunks of pieces count their pairs per top cell in
/// parallel, the counts are prefix-summed (top cell major, chunk minor), and each chunk writes
/// its pieces at its own offsets. The result does not depend on the chunking. `range(i)` is
/// piece `i`'s inclusive range of top cells, `None` to leave it out. `None` if the pairs are
/// more than `most_pairs` (a chunk with more stops counting at once) or overflow.
fn group_by_top_cell(
    n: usize,
    top_cells: usize,
    range: impl Fn(usize) -> Option<([u32; 3], [u32; 3])> + Sync,
    res: [u32; 3],
    most_pairs: u64,
) -> Option<(Vec<usize>, Vec<u32>)> {
    // Chunks: a few per thread, but their counts together within a memory budget.
    let chunks = (4 * rayon::current_num_threads())
        .min(n.div_ceil(CHUNK))
        .min((HISTOGRAM_BUDGET / top_cells.max(1)).max(1))
        .max(1);
    let size = n.div_ceil(chunks).max(1);
    let bounds = |c: usize| (c * size).min(n)..((c + 1) * size).min(n);
    let mut hist: Vec<Vec<usize>> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut h = vec![0usize; top_cells];
            let mut pairs = 0u64;
            for i in bounds(c) {
                if let Some((lo, hi)) = range(i) {
                    pairs += range_size(lo, hi);
                    if pairs > most_pairs {
                        return None;
                    }
                    for_each_cell(lo, hi, |cell| h[linear(cell, res)] += 1);
                }
            }
            Some(h)
        })
        .collect::<Option<_>>()?;
    // Top cell major, chunk minor: `hist[c][t]` becomes chunk c's first slot in top cell t.
    let mut begin = Vec::with_capacity(top_cells + 1);
    let mut total = 0usize;
    for t in 0..top_cells {
        begin.push(total);
        for h in hist.iter_mut() {
            let c = h[t];
            h[t] = total;
            total = total.checked_add(c)?;
        }
    }
    begin.push(total);
    if total as u64 >= 1 << 36 || total as u64 > most_pairs {
        return None;
    }
    // Every slot is written by exactly one chunk; relaxed atomic stores are plain stores.
    let out: Vec<AtomicU32> = (0..total)
        .into_par_iter()
        .map(|_| AtomicU32::new(0))
        .collect();
    hist.into_par_iter().enumerate().for_each(|(c, mut next)| {
        for i in bounds(c) {
            if let Some((lo, hi)) = range(i) {
                for_each_cell(lo, hi, |cell| {
                    let k = &mut next[linear(cell, res)];
                    out[*k].store(i as u32, Ordering::Relaxed);
                    *k += 1;
                });
            }
        }
    });
    let refs = out.into_iter().map(AtomicU32::into_inner).collect();
    Some((begin, refs))
}

/// The number of cells of the inclusive index range (none if it is empty on some axis).
#[inline]
fn range_size(lo: [u32; 3], hi: [u32; 3]) -> u64 {
    (0..3)
        .map(|a| (hi[a] as u64 + 1).saturating_sub(lo[a] as u64))
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

/// The share of leaf cell `c` (of the leaf frame with origin `origin` and cell size `size`)
/// that box `b` covers, as a product of the covered fractions along each axis (an axis of
/// zero size counts as covered).
fn overlap_share(b: &Aabb, origin: DVec3, size: DVec3, c: [u32; 3]) -> f32 {
    let mut share = 1.0;
    for a in 0..3 {
        if size[a] > 0.0 {
            let lo = origin[a] + c[a] as f64 * size[a];
            let hi = lo + size[a];
            let covered = (b.max[a].min(hi) - b.min[a].max(lo)).clamp(0.0, size[a]);
            share *= covered / size[a];
        }
    }
    share as f32
}
