//! The parallel binned-SAH build ([`build_bvh`]).

use std::marker::PhantomData;
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::bounds::{BvhBounds, LinearFrame};
use super::{Bvh, BvhParams, Node, Ref, MAX_DEPTH};
use crate::accel::space::Pieces;
use crate::geometry::bounds::Aabb;

/// Most SAH bins per axis.
pub(crate) const MAX_BINS: usize = 32;

/// Nodes with more pieces than this build their two subtrees in parallel.
const PARALLEL_THRESHOLD: usize = 8192;

/// Beyond this depth nodes split at the median piece, so depth stays below [`MAX_DEPTH`].
const MEDIAN_DEPTH: usize = 48;

/// Builds a BVH over the pieces with the binned surface-area heuristic (see the
/// [module documentation](super)). Pieces beyond the shorter of `bounds` and `cells` are
/// ignored; empty bounds are kept (in some leaf) but contain nothing. Never panics on any
/// bounds (NaN included), but needs fewer than 2³² pieces.
///
/// ```
/// use cylvol::accel::bvh::{build_bvh, BvhParams};
/// use cylvol::accel::space::Pieces;
/// use cylvol::geometry::bounds::Aabb;
/// use glam::DVec3;
/// let bounds: Vec<Aabb> = (0..100)
///     .map(|i| Aabb::new(DVec3::splat(i as f64), DVec3::splat(i as f64 + 1.0)))
///     .collect();
/// let pieces = Pieces { cells: (0..100).collect(), bounds };
/// let bvh = build_bvh(&pieces, &BvhParams::default());
/// assert_eq!(bvh.stats().references, 100);
/// bvh.assert_well_formed(&pieces);
/// ```
pub fn build_bvh<B: BvhBounds>(pieces: &Pieces<B>, params: &BvhParams) -> Bvh<B> {
    let start = Instant::now();
    let params = params.sanitized();
    let n = pieces.bounds.len().min(pieces.cells.len());
    let n = n.min(u32::MAX as usize - 1);
    let bounds = &pieces.bounds[..n];
    let root = B::union_all(bounds);
    let frame = B::frame_of(&root);
    let mut items: Vec<Item> = bounds
        .par_iter()
        .enumerate()
        .map(|(i, b)| {
            let lin = b.linearize(&frame);
            Item {
                lin,
                piece: i as u32,
            }
        })
        .collect();
    let nodes = if n == 0 {
        Vec::new()
    } else {
        let ctx = Ctx::<B> {
            frame,
            params,
            _b: PhantomData,
        };
        let built = ctx.build_par(&mut items, 0, 0, None);
        let mut nodes = Vec::with_capacity(built.len());
        flatten(built, &mut nodes);
        nodes
    };
    let refs: Vec<Ref<B::Compact>> = items
        .par_iter()
        .map(|it| Ref {
            bounds: B::compact(&it.lin, &frame),
            cell: pieces.cells[it.piece as usize],
        })
        .collect();
    Bvh {
        nodes,
        refs,
        frame,
        params,
        build_s: start.elapsed().as_secs_f64(),
        _bounds: PhantomData,
    }
}

/// A subtree: built in one piece (indices local to its vector) or split in parallel.
enum Built<C> {
    Flat(Vec<Node<C>>),
    Split {
        node: Node<C>,
        left: Box<Built<C>>,
        right: Box<Built<C>>,
    },
}

impl<C> Built<C> {
    fn len(&self) -> usize {
        match self {
            Built::Flat(v) => v.len(),
            Built::Split { left, right, .. } => 1 + left.len() + right.len(),
        }
    }
}

fn flatten<C: Copy>(built: Built<C>, out: &mut Vec<Node<C>>) {
    match built {
        Built::Flat(v) => {
            let base = out.len() as u32;
            out.extend(v.into_iter().map(|mut node| {
                if node.count == 0 {
                    node.index += base;
                }
                node
            }));
        }
        Built::Split { node, left, right } => {
            let at = out.len();
            out.push(node);
            flatten(*left, out);
            out[at].index = out.len() as u32;
            flatten(*right, out);
        }
    }
}

/// A piece during the build: its linear box and its index. The build partitions these in
/// place, so every pass reads them in order; they are kept small (the centre is recomputed
/// where needed) because the passes over them are bound by memory.
#[derive(Clone, Copy)]
struct Item {
    lin: Aabb,
    piece: u32,
}

impl Item {
    /// The centre of the linear box.
    #[inline]
    fn centre(&self) -> DVec3 {
        self.lin.center()
    }
}

/// `b` grown to hold `l`: [`Aabb::union`] for a `b` without NaN (as every bin and node box
/// built from [`Aabb::EMPTY`] by unions is), by plain comparisons.
#[inline]
fn merge(b: &mut Aabb, l: &Aabb) {
    b.min = DVec3::select(l.min.cmplt(b.min), l.min, b.min);
    b.max = DVec3::select(l.max.cmpgt(b.max), l.max, b.max);
}

struct Ctx<B> {
    frame: LinearFrame,
    params: BvhParams,
    _b: PhantomData<B>,
}

/// A node's bounds (the union of its pieces' linear boxes) and the box of their centroids.
type Scan = (Aabb, Aabb);

/// The cheapest SAH split of a node: the axis, the first bin on the right, its cost, and the
/// bounds of the two sides.
struct BestSplit {
    axis: usize,
    bin: usize,
    cost: f64,
    left: Aabb,
    right: Aabb,
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Aabb::EMPTY,
    count: 0,
};

/// The bin of a centroid coordinate (NaN goes to bin 0, like the partition).
#[inline]
fn bin_of(c: f64, min: f64, scale: f64, bins: usize) -> usize {
    (((c - min) * scale) as usize).min(bins - 1)
}

impl<B: BvhBounds> Ctx<B> {
    /// The union of the pieces' linear boxes and the box of their centroids.
    fn scan(&self, idx: &[Item]) -> (Aabb, Aabb) {
        let fold = |(b, c): (Aabb, Aabb), it: &Item| {
            let l = &it.lin;
            (
                b.union(l),
                if l.is_empty() { c } else { c.grow(it.centre()) },
            )
        };
        if idx.len() > PARALLEL_THRESHOLD {
            idx.par_iter()
                .fold(|| (Aabb::EMPTY, Aabb::EMPTY), fold)
                .reduce(
                    || (Aabb::EMPTY, Aabb::EMPTY),
                    |a, b| (a.0.union(&b.0), a.1.union(&b.1)),
                )
        } else {
            idx.iter().fold((Aabb::EMPTY, Aabb::EMPTY), fold)
        }
    }

    fn node(&self, bounds: &Aabb, count: u32, index: u32) -> Node<B::Compact> {
        Node {
            bounds: B::compact(bounds, &self.frame),
            count,
            index,
        }
    }

    /// Builds the subtree over `idx`; `known` is its bounds and centroid box when the parent's
    /// split already computed them (else they are scanned).
    fn build_par(
        &self,
        idx: &mut [Item],
        offset: usize,
        depth: usize,
        known: Option<Scan>,
    ) -> Built<B::Compact> {
        if idx.len() <= PARALLEL_THRESHOLD {
            let mut out = Vec::with_capacity(2 * idx.len() / self.params.max_leaf_size + 1);
            self.build_seq(idx, offset, depth, known, &mut out);
            return Built::Flat(out);
        }
        let (bounds, centroids) = known.unwrap_or_else(|| self.scan(idx));
        match self.split(idx, &bounds, &centroids, depth) {
            None => Built::Flat(vec![self.node(&bounds, idx.len() as u32, offset as u32)]),
            Some((mid, [kl, kr])) => {
                let (l, r) = idx.split_at_mut(mid);
                let (left, right) = rayon::join(
                    || self.build_par(l, offset, depth + 1, kl),
                    || self.build_par(r, offset + mid, depth + 1, kr),
                );
                Built::Split {
                    node: self.node(&bounds, 0, 0),
                    left: Box::new(left),
                    right: Box::new(right),
                }
            }
        }
    }

    fn build_seq(
        &self,
        idx: &mut [Item],
        offset: usize,
        depth: usize,
        known: Option<Scan>,
        out: &mut Vec<Node<B::Compact>>,
    ) {
        let (bounds, centroids) = known.unwrap_or_else(|| self.scan(idx));
        let at = out.len();
        match self.split(idx, &bounds, &centroids, depth) {
            None => out.push(self.node(&bounds, idx.len() as u32, offset as u32)),
            Some((mid, [kl, kr])) => {
                out.push(self.node(&bounds, 0, 0));
                let (l, r) = idx.split_at_mut(mid);
                self.build_seq(l, offset, depth + 1, kl, out);
                out[at].index = out.len() as u32;
                self.build_seq(r, offset + mid, depth + 1, kr, out);
            }
        }
    }

    /// Where to split the node (after partitioning `idx`), or `None` for a leaf; with the
    /// split, the two sides' bounds and centroid boxes where the SAH split found them.
    fn split(
        &self,
        idx: &mut [Item],
        bounds: &Aabb,
        cent: &Aabb,
        depth: usize,
    ) -> Option<(usize, [Option<Scan>; 2])> {
        let n = idx.len();
        let max_leaf = self.params.max_leaf_size;
        if n <= 1 {
            return None;
        }
        if depth < MEDIAN_DEPTH {
            let area = B::linear_area(bounds);
            if let Some(best) = self.best_bin_split(idx, cent, area) {
                let leaf_cost = n as f64 * area;
                if n <= max_leaf && leaf_cost <= best.cost {
                    return None;
                }
                let (mid, [cl, cr]) = self.partition(idx, cent, best.axis, best.bin);
                if mid > 0 && mid < n {
                    return Some((mid, [Some((best.left, cl)), Some((best.right, cr))]));
                }
            }
        }
        if n <= max_leaf {
            return None;
        }
        Some((self.median_split(idx, cent), [None, None]))
    }

    /// Bins for a node of `n` pieces: no more than pieces.
    fn bins_for(&self, n: usize) -> usize {
        self.params.bins.min(n).max(2)
    }

    /// The cheapest bin boundary.
    fn best_bin_split(&self, idx: &[Item], cent: &Aabb, area: f64) -> Option<BestSplit> {
        let k = self.bins_for(idx.len());
        // Bin arrays sized to the node: small nodes, the most numerous, clear little memory.
        if k <= 4 {
            self.best_bin_split_in::<4>(idx, cent, area, k)
        } else if k <= 8 {
            self.best_bin_split_in::<8>(idx, cent, area, k)
        } else if k <= 16 {
            self.best_bin_split_in::<16>(idx, cent, area, k)
        } else {
            self.best_bin_split_in::<MAX_BINS>(idx, cent, area, k)
        }
    }

    fn best_bin_split_in<const K: usize>(
        &self,
        idx: &[Item],
        cent: &Aabb,
        area: f64,
        k: usize,
    ) -> Option<BestSplit> {
        let k = k.min(K);
        let ext = cent.extent();
        let min = cent.min;
        let s = |e: f64| {
            let s = k as f64 / e;
            if e > 0.0 && s.is_finite() {
                s
            } else {
                0.0
            }
        };
        let scale = DVec3::new(s(ext.x), s(ext.y), s(ext.z));
        if scale == DVec3::ZERO {
            return None;
        }
        let fill = |chunk: &[Item]| {
            let mut bins = [[EMPTY_BIN; K]; 3];
            for it in chunk {
                let l = &it.lin;
                let c = it.centre();
                for a in 0..3 {
                    if scale[a] > 0.0 {
                        let b = &mut bins[a][bin_of(c[a], min[a], scale[a], k)];
                        merge(&mut b.bounds, l);
                        b.count += 1;
                    }
                }
            }
            bins
        };
        // Bins are unions and counts, so binning in parallel chunks gives the same bins.
        let bins = if idx.len() > PARALLEL_THRESHOLD {
            idx.par_chunks(PARALLEL_THRESHOLD)
                .map(fill)
                .reduce_with(|mut a, b| {
                    for (a, b) in a.iter_mut().flatten().zip(b.iter().flatten()) {
                        a.bounds = a.bounds.union(&b.bounds);
                        a.count += b.count;
                    }
                    a
                })
                .unwrap_or([[EMPTY_BIN; K]; 3])
        } else {
            fill(idx)
        };
        let traversal = self.params.traversal_cost * area;
        let mut best: Option<BestSplit> = None;
        for (a, bins) in bins.iter().enumerate() {
            if scale[a] <= 0.0 {
                continue;
            }
            // Right-hand areas × counts (and bounds) for splits before bin s.
            let mut right_cost = [0.0f64; K];
            let mut right_bounds = [Aabb::EMPTY; K];
            let mut acc = EMPTY_BIN;
            for s in (1..k).rev() {
                acc.bounds = acc.bounds.union(&bins[s].bounds);
                acc.count += bins[s].count;
                right_bounds[s] = acc.bounds;
                right_cost[s] = if acc.count == 0 {
                    f64::NAN
                } else {
                    B::linear_area(&acc.bounds) * acc.count as f64
                };
            }
            let mut left = EMPTY_BIN;
            for s in 1..k {
                left.bounds = left.bounds.union(&bins[s - 1].bounds);
                left.count += bins[s - 1].count;
                if left.count == 0 || right_cost[s].is_nan() {
                    continue;
                }
                let cost =
                    traversal + B::linear_area(&left.bounds) * left.count as f64 + right_cost[s];
                if best.as_ref().map_or(true, |b| cost < b.cost) {
                    best = Some(BestSplit {
                        axis: a,
                        bin: s,
                        cost,
                        left: left.bounds,
                        right: right_bounds[s],
                    });
                }
            }
        }
        best
    }

    /// Moves the pieces whose centroid falls in a bin before `bin` to the front; returns
    /// how many they are and the centroid boxes of the two sides (as [`Ctx::scan`] would).
    fn partition(
        &self,
        idx: &mut [Item],
        cent: &Aabb,
        axis: usize,
        bin: usize,
    ) -> (usize, [Aabb; 2]) {
        let k = self.bins_for(idx.len());
        let min = cent.min[axis];
        let scale = k as f64 / cent.extent()[axis];
        let left = |it: &Item| bin_of(it.centre()[axis], min, scale, k) < bin;
        let grow = |c: Aabb, it: &Item| {
            if it.lin.is_empty() {
                c
            } else {
                c.grow(it.centre())
            }
        };
        let (mut lo, mut hi) = (0usize, idx.len());
        let (mut cl, mut cr) = (Aabb::EMPTY, Aabb::EMPTY);
        while lo < hi {
            if left(&idx[lo]) {
                cl = grow(cl, &idx[lo]);
                lo += 1;
            } else {
                cr = grow(cr, &idx[lo]);
                hi -= 1;
                idx.swap(lo, hi);
            }
        }
        (lo, [cl, cr])
    }

    /// Halves the pieces at the median centroid along the centroids' longest axis.
    fn median_split(&self, idx: &mut [Item], cent: &Aabb) -> usize {
        let ext = cent.extent();
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = idx.len() / 2;
        let key = |it: &Item| it.centre()[axis];
        idx.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
        mid
    }
}

const _: () = assert!(MEDIAN_DEPTH + 40 < MAX_DEPTH);
