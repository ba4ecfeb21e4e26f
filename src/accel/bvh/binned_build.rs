//! The parallel binned-SAH build ([`build_bvh`]).

use std::marker::PhantomData;
use std::time::Instant;

use glam::{BVec4A, Vec3A, Vec4};
use rayon::prelude::*;

use super::bounds::BvhBounds;
use super::{Bvh, BvhParams, Node, Ref, MAX_DEPTH};
use crate::accel::space::Pieces;

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
            let (lo, hi) = B::compact_corners(&B::compact(&b.linearize(&frame), &frame));
            Item::new(lo, hi, i as u32)
        })
        .collect();
    let nodes = if n == 0 {
        Vec::new()
    } else {
        let ctx = Ctx::<B> {
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
            bounds: B::compact_from_corners(it.lo().to_array(), it.hi().to_array()),
            cell: pieces.cells[it.piece()],
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

/// A piece during the build: the corners of its stored bound ([`BvhBounds::compact_corners`],
/// `f32`) and its index, in 32 aligned bytes (the index as the bits of the low corner's fourth
/// lane, masked off before any arithmetic, so it never meets a floating-point operation). The
/// build partitions these in place, so every pass reads them in order; they are kept small
/// (the centre is recomputed where needed) because the passes over them are bound by memory.
#[derive(Clone, Copy)]
#[repr(C)]
struct Item {
    lo_piece: Vec4,
    hi: Vec3A,
}

/// The three coordinate lanes of a [`Vec4`].
const XYZ: BVec4A = BVec4A::new(true, true, true, false);

impl Item {
    fn new(lo: [f32; 3], hi: [f32; 3], piece: u32) -> Item {
        Item {
            lo_piece: Vec4::new(lo[0], lo[1], lo[2], f32::from_bits(piece)),
            hi: Vec3A::from_array(hi),
        }
    }

    #[inline]
    fn lo(&self) -> Vec3A {
        Vec3A::from_vec4(Vec4::select(XYZ, self.lo_piece, Vec4::ZERO))
    }

    #[inline]
    fn hi(&self) -> Vec3A {
        self.hi
    }

    #[inline]
    fn piece(&self) -> usize {
        self.lo_piece.w.to_bits() as usize
    }

    /// The centre of the stored bound's corners (NaN for an empty bound).
    #[inline]
    fn centre(&self) -> Vec3A {
        (self.lo() + self.hi()) * 0.5
    }
}

/// A box of corners in `f32`: a node's or a bin's bound, or a box of centres. Unions of the
/// pieces' stored corners are exact, so a node's stored bound is the same, bit for bit, as the
/// stored form of the union of its pieces' `f64` bounds.
#[derive(Clone, Copy)]
struct Corners {
    lo: Vec3A,
    hi: Vec3A,
}

impl Corners {
    const EMPTY: Corners = Corners {
        lo: Vec3A::INFINITY,
        hi: Vec3A::NEG_INFINITY,
    };

    /// Grown to hold the box `[lo, hi]` (never NaN: pieces' corners are not, and an empty
    /// bound's `±∞` corners leave the box as it is).
    #[inline]
    fn merge(&mut self, lo: Vec3A, hi: Vec3A) {
        self.lo = lo.min(self.lo);
        self.hi = hi.max(self.hi);
    }

    /// Grown to hold the point `m`, unless it has a NaN coordinate (the centre of an empty
    /// bound), which is passed over: tested rather than left to `min`/`max`, whose NaN rule
    /// differs between glam's SSE2 and NEON forms.
    #[inline]
    fn merge_point(&mut self, m: Vec3A) {
        if !m.is_nan() {
            self.merge(m, m);
        }
    }

    #[inline]
    fn union(mut self, o: &Corners) -> Corners {
        self.merge(o.lo, o.hi);
        self
    }

    /// The extent, zero on an axis where the box is empty.
    fn extent(&self) -> Vec3A {
        (self.hi - self.lo).max(Vec3A::ZERO)
    }

    /// The surface area, in world units, of the bound these corners stand for (the
    /// heuristic's `A`, [`BvhBounds::corners_area`]; the padding of stored arcs widens them
    /// by far less than their `f32` rounding).
    fn area<B: BvhBounds>(&self) -> f64 {
        if !self.lo.cmple(self.hi).all() {
            return 0.0;
        }
        B::corners_area(self.lo.to_array(), self.hi.to_array())
    }
}

struct Ctx<B> {
    params: BvhParams,
    _b: PhantomData<B>,
}

/// A node's bounds (the union of its pieces' corners) and the box of their centres.
type Scan = (Corners, Corners);

/// The cheapest SAH split of a node: the axis, the first bin on the right, its cost, and the
/// bounds of the two sides.
struct BestSplit {
    axis: usize,
    bin: usize,
    cost: f64,
    left: Corners,
    right: Corners,
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Corners,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Corners::EMPTY,
    count: 0,
};

/// How a node's centres are binned: bin `⌊(c − min) · scale⌋` (at most the last) along each
/// axis whose scale is not zero. Binning and partitioning use the same arithmetic, so a piece
/// goes to the side its bin was counted on.
#[derive(Clone, Copy)]
struct Binning {
    min: Vec3A,
    scale: Vec3A,
    bins: usize,
}

impl Binning {
    /// `bins` bins over the centres' box, or `None` when the centres are all one point.
    fn new(cent: &Corners, bins: usize) -> Option<Binning> {
        let ext = cent.extent();
        let s = |e: f32| {
            let s = bins as f32 / e;
            if e > 0.0 && s.is_finite() {
                s
            } else {
                0.0
            }
        };
        let scale = Vec3A::new(s(ext.x), s(ext.y), s(ext.z));
        (scale != Vec3A::ZERO).then_some(Binning {
            min: cent.lo,
            scale,
            bins,
        })
    }

    /// The bins of a centre along each axis (NaN goes to bin 0).
    #[inline]
    fn bins_of(&self, c: Vec3A) -> [usize; 3] {
        let v = ((c - self.min) * self.scale).to_array();
        v.map(|x| (x as usize).min(self.bins - 1))
    }

    /// The bin of a centre along one axis: `bins_of(c)[axis]`.
    #[inline]
    fn bin_of(&self, c: Vec3A, axis: usize) -> usize {
        (((c[axis] - self.min[axis]) * self.scale[axis]) as usize).min(self.bins - 1)
    }
}

impl<B: BvhBounds> Ctx<B> {
    /// The union of the pieces' corners and the box of their centres.
    fn scan(&self, idx: &[Item]) -> Scan {
        let fold = |(mut b, mut c): Scan, it: &Item| {
            b.merge(it.lo(), it.hi());
            c.merge_point(it.centre());
            (b, c)
        };
        if idx.len() > PARALLEL_THRESHOLD {
            idx.par_iter()
                .fold(|| (Corners::EMPTY, Corners::EMPTY), fold)
                .reduce(
                    || (Corners::EMPTY, Corners::EMPTY),
                    |a, b| (a.0.union(&b.0), a.1.union(&b.1)),
                )
        } else {
            idx.iter().fold((Corners::EMPTY, Corners::EMPTY), fold)
        }
    }

    fn node(&self, bounds: &Corners, count: u32, index: u32) -> Node<B::Compact> {
        Node {
            bounds: B::compact_from_corners(bounds.lo.to_array(), bounds.hi.to_array()),
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
    /// split, the two sides' bounds and centre boxes where the SAH split found them.
    fn split(
        &self,
        idx: &mut [Item],
        bounds: &Corners,
        cent: &Corners,
        depth: usize,
    ) -> Option<(usize, [Option<Scan>; 2])> {
        let n = idx.len();
        let max_leaf = self.params.max_leaf_size;
        if n <= 1 {
            return None;
        }
        if depth < MEDIAN_DEPTH {
            let area = bounds.area::<B>();
            if let Some((best, binning)) = self.best_bin_split(idx, cent, area) {
                let leaf_cost = n as f64 * area;
                if n <= max_leaf && leaf_cost <= best.cost {
                    return None;
                }
                let (mid, [cl, cr]) = partition(idx, &binning, best.axis, best.bin);
                if mid > 0 && mid < n {
                    return Some((mid, [Some((best.left, cl)), Some((best.right, cr))]));
                }
            }
        }
        if n <= max_leaf {
            return None;
        }
        Some((median_split(idx, cent), [None, None]))
    }

    /// Bins for a node of `n` pieces: no more than pieces.
    fn bins_for(&self, n: usize) -> usize {
        self.params.bins.min(n).max(2)
    }

    /// The cheapest bin boundary, and the binning it was found with.
    fn best_bin_split(
        &self,
        idx: &[Item],
        cent: &Corners,
        area: f64,
    ) -> Option<(BestSplit, Binning)> {
        let k = self.bins_for(idx.len());
        // Bin arrays sized to the node: small nodes, the most numerous, clear little memory.
        let binning = Binning::new(cent, k)?;
        let best = if k <= 4 {
            self.best_bin_split_in::<4>(idx, &binning, area)
        } else if k <= 8 {
            self.best_bin_split_in::<8>(idx, &binning, area)
        } else if k <= 16 {
            self.best_bin_split_in::<16>(idx, &binning, area)
        } else {
            self.best_bin_split_in::<MAX_BINS>(idx, &binning, area)
        }?;
        Some((best, binning))
    }

    fn best_bin_split_in<const K: usize>(
        &self,
        idx: &[Item],
        binning: &Binning,
        area: f64,
    ) -> Option<BestSplit> {
        let k = binning.bins.min(K);
        let live = binning.scale.cmpgt(Vec3A::ZERO).bitmask();
        let fill = |chunk: &[Item]| {
            let mut bins = [[EMPTY_BIN; K]; 3];
            for it in chunk {
                let (lo, hi) = (it.lo(), it.hi());
                let at = binning.bins_of(it.centre());
                for (a, bins) in bins.iter_mut().enumerate() {
                    if live & (1 << a) != 0 {
                        let b = &mut bins[at[a]];
                        b.bounds.merge(lo, hi);
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
            if live & (1 << a) == 0 {
                continue;
            }
            // A split before bin s whose bin s − 1 is empty has both sides, and so its cost,
            // the same as the split before bin s − 1, which the sweep meets first and keeps
            // (only a strictly cheaper split replaces the best): such splits are not costed.
            let costed = |s: usize| bins[s - 1].count != 0;
            // Right-hand areas × counts (and bounds) for splits before bin s.
            let mut right_cost = [f64::NAN; K];
            let mut right_bounds = [Corners::EMPTY; K];
            let mut acc = EMPTY_BIN;
            for s in (1..k).rev() {
                acc.bounds = acc.bounds.union(&bins[s].bounds);
                acc.count += bins[s].count;
                right_bounds[s] = acc.bounds;
                if acc.count != 0 && costed(s) {
                    right_cost[s] = acc.bounds.area::<B>() * acc.count as f64;
                }
            }
            let mut left = EMPTY_BIN;
            for s in 1..k {
                left.bounds = left.bounds.union(&bins[s - 1].bounds);
                left.count += bins[s - 1].count;
                if left.count == 0 || !costed(s) || right_cost[s].is_nan() {
                    continue;
                }
                let cost = traversal + left.bounds.area::<B>() * left.count as f64 + right_cost[s];
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
}

/// Moves the pieces whose centre falls in a bin before `bin` along `axis` to the front;
/// returns how many they are and the centre boxes of the two sides (as [`Ctx::scan`] makes
/// them).
fn partition(
    idx: &mut [Item],
    binning: &Binning,
    axis: usize,
    bin: usize,
) -> (usize, [Corners; 2]) {
    let (mut lo, mut hi) = (0usize, idx.len());
    let (mut cl, mut cr) = (Corners::EMPTY, Corners::EMPTY);
    while lo < hi {
        let m = idx[lo].centre();
        if binning.bin_of(m, axis) < bin {
            cl.merge_point(m);
            lo += 1;
        } else {
            cr.merge_point(m);
            hi -= 1;
            idx.swap(lo, hi);
        }
    }
    (lo, [cl, cr])
}

/// Halves the pieces at the median centre along the centres' longest axis.
fn median_split(idx: &mut [Item], cent: &Corners) -> usize {
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

const _: () = assert!(MEDIAN_DEPTH + 40 < MAX_DEPTH);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::bounds::Aabb;

    /// The split the sweep must choose, found by costing every split from scratch in the
    /// sweep's order (axis, then bin) and keeping the first of the cheapest: axis, bin and
    /// the cost's bits.
    fn every_split_costed(
        idx: &[Item],
        binning: &Binning,
        area: f64,
        traversal_cost: f64,
    ) -> Option<(usize, usize, u64)> {
        let k = binning.bins;
        let mut best: Option<(usize, usize, f64)> = None;
        for axis in (0..3).filter(|&a| binning.scale[a] > 0.0) {
            for s in 1..k {
                let (mut left, mut right) = (EMPTY_BIN, EMPTY_BIN);
                for it in idx {
                    let side = if binning.bins_of(it.centre())[axis] < s {
                        &mut left
                    } else {
                        &mut right
                    };
                    side.bounds.merge(it.lo(), it.hi());
                    side.count += 1;
                }
                if left.count == 0 || right.count == 0 {
                    continue;
                }
                let cost = traversal_cost * area
                    + left.bounds.area::<Aabb>() * left.count as f64
                    + right.bounds.area::<Aabb>() * right.count as f64;
                if best.is_none_or(|b| cost < b.2) {
                    best = Some((axis, s, cost));
                }
            }
        }
        best.map(|(a, s, c)| (a, s, c.to_bits()))
    }

    /// Boxes whose centres gather in a few clusters (so most bins stay empty) or spread
    /// evenly, some of them repeated, from a fixed seed.
    fn items(n: usize, clusters: usize, seed: u64) -> Vec<Item> {
        let mut state = seed | 1;
        let mut unit = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let centres: Vec<[f32; 3]> = (0..clusters.max(1))
            .map(|_| [unit() * 100.0, unit() * 100.0, unit() * 100.0])
            .collect();
        (0..n)
            .map(|i| {
                let c = if clusters == 0 {
                    [unit() * 100.0, unit() * 100.0, unit() * 100.0]
                } else {
                    centres[i % centres.len()].map(|x| x + unit() * 0.01)
                };
                let half = unit() * 3.0;
                Item::new(c.map(|x| x - half), c.map(|x| x + half), i as u32)
            })
            .collect()
    }

    #[test]
    fn the_sweep_chooses_the_split_that_costing_every_split_chooses() {
        let ctx = Ctx::<Aabb> {
            params: BvhParams::default().sanitized(),
            _b: PhantomData,
        };
        let mut compared = 0;
        for seed in 0..200u64 {
            for (n, clusters) in [(3, 0), (7, 2), (20, 3), (33, 0), (100, 5), (500, 9)] {
                let idx = items(n, clusters, seed * 7919 + n as u64);
                let (bounds, cent) = ctx.scan(&idx);
                let area = bounds.area::<Aabb>();
                let Some((best, binning)) = ctx.best_bin_split(&idx, &cent, area) else {
                    continue;
                };
                let want = every_split_costed(&idx, &binning, area, ctx.params.traversal_cost);
                assert_eq!(
                    Some((best.axis, best.bin, best.cost.to_bits())),
                    want,
                    "seed {seed}, {n} pieces in {clusters} clusters"
                );
                compared += 1;
            }
        }
        assert!(compared > 1000, "{compared} nodes compared");
    }
}
