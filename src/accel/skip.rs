//! The structures' ray contract: the stretches of a ray that may hold the cells a ray looks
//! for, each structure by its own traversal (a BVH's closest-hit traversal of its nodes in its
//! own frame, [`super::bvh`]; a grid's walk from grid cell to grid cell), so that the
//! renderer never asks which structure it has.
//!
//! - **Empty space** ([`Accel::next_bound`], [`Accel::may_hold`]): where along a ray the next
//!   sample may lie in a piece's bound, so samples outside every bound (the hub's hole, the
//!   corners of the mesh's box) are passed over without point location. A BVH gives the first
//!   bound the ray enters and its exit from it; a grid passes a sample over when its
//!   second-level cell holds no reference (one top-cell and one leaf-cell look-up, no cell
//!   tested).
//! - **Kept cells** ([`Accel::mark_cells`], [`Accel::next_marked`]): a structure marks where
//!   the cells a ray looks for lie (a BVH per node, a grid per grid cell) and gives the first
//!   stretch of the ray that may meet one — for the renderer, the cells the transfer function
//!   does not make wholly transparent.
//! - **Ranges** ([`Accel::node_ranges`], [`Accel::next_in_ranges`]): a BVH keeps the range of
//!   a per-cell interval below each node and gives the first stretch that may meet a cell
//!   whose interval passes a test — for an intensity projection, the cells whose scalar range
//!   may beat the ray's extreme. A grid keeps none: its rays do not jump there.
//!
//! Every answer is **conservative**: bounds are padded by `1e-9` of the root's extent before
//! the ray is intersected with them, so a point the structure could locate is never skipped.

use glam::DVec3;

use super::bvh::{NodeMask, NodeRanges};
use super::grid::GridMask;
use super::{Accel, Coordinates, Counters, RaySpan, Structure};

/// Where a structure holds the cells a ray looks for ([`Accel::mark_cells`]): per BVH node,
/// or per grid cell.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum CellMarks {
    /// The BVH nodes holding a piece of a kept cell.
    Nodes(NodeMask),
    /// The grid cells referencing a kept cell.
    Grid(GridMask),
}

impl Accel {
    /// For a BVH: the first stretch of `span` in which the ray (unit direction) may lie in a
    /// piece's bound, `(entry, exit)` such that it lies in one piece's bound from `entry` to
    /// `exit` (so no sample in between need ask again); `None` if it lies in none on the span.
    /// For a grid: `(t0, t0)` (grids are skipped sample by sample, see [`Accel::may_hold`]).
    /// Node visits are counted in `counters`.
    pub(crate) fn next_bound(&self, span: RaySpan, counters: &mut Counters) -> Option<(f64, f64)> {
        match self.first_kept_piece(span, |_| true, |_| true, counters) {
            Some(hit) => hit.map(|(e, x, _)| (e, x)),
            // A grid, or a cylindrical BVH without its frame: no bounds to traverse.
            None => Some((span.t0, span.t0)),
        }
    }

    /// Whether the structure may hold a cell at `p`: for a grid, whether `p`'s second-level
    /// cell holds references (one top and one leaf visit counted); for a BVH, always `true`.
    pub(crate) fn may_hold(&self, p: DVec3, counters: &mut Counters) -> bool {
        match self.structure() {
            Structure::Grid(g) => {
                let q = self.coordinates().query(p);
                if !g.domain().contains(q) {
                    return false;
                }
                counters.internal_visits += 1;
                counters.leaf_visits += 1;
                !g.candidates(q).is_empty()
            }
            _ => true,
        }
    }

    /// Where the cells that `keep` keeps lie in the structure: a BVH's nodes holding a piece
    /// of one, or a grid's cells referencing one; made in parallel, or on the calling thread
    /// alone (for marks made lazily, whose maker must not wait on work the thread pool might
    /// hand back to it).
    pub(crate) fn mark_cells(
        &self,
        keep: impl Fn(u32) -> bool + Sync,
        parallel: bool,
    ) -> CellMarks {
        match (self.structure(), parallel) {
            (Structure::Grid(g), true) => CellMarks::Grid(g.cells_holding(keep)),
            (Structure::Grid(g), false) => CellMarks::Grid(g.cells_holding_sequential(keep)),
            (Structure::CartBvh(b), true) => CellMarks::Nodes(b.nodes_holding(keep)),
            (Structure::CartBvh(b), false) => CellMarks::Nodes(b.nodes_holding_sequential(keep)),
            (Structure::CylBvh(b), true) => CellMarks::Nodes(b.nodes_holding(keep)),
            (Structure::CylBvh(b), false) => CellMarks::Nodes(b.nodes_holding_sequential(keep)),
        }
    }

    /// The first `t` of `span` from which the ray may meet a cell of `marks` that `keep`
    /// keeps (`marks` made by [`Accel::mark_cells`] with `keep`), with the ray's exit from the
    /// bound or grid cell it lies in there and, where the structure names one, such a cell
    /// (a hint for locating the point there); `None` where there is none on the span, or the
    /// marks were made for another structure. The ray meets no kept cell before the answer.
    /// A grid's walk may stop short of a kept cell (at the edge of its domain, say) with no
    /// hint. Node or grid cell visits are counted in `counters`.
    pub(crate) fn next_marked(
        &self,
        span: RaySpan,
        marks: &CellMarks,
        keep: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, Option<u32>)> {
        match (self.structure(), marks) {
            (Structure::Grid(g), CellMarks::Grid(mask)) => {
                g.next_marked(span, mask, keep, counters)
            }
            (Structure::Grid(_), _) => None,
            (_, CellMarks::Nodes(nodes)) => self
                .next_in_nodes(span, nodes.len(), |i| nodes.contains(i), keep, counters)
                .map(|(e, x, c)| (e, x, Some(c))),
            (_, CellMarks::Grid(_)) => None,
        }
    }

    /// The union of `range` over the cells below each of a BVH's nodes (`None` for a grid),
    /// made in parallel or on the calling thread alone (see [`Accel::mark_cells`]).
    pub(crate) fn node_ranges(
        &self,
        range: impl Fn(u32) -> [f64; 2] + Sync,
        parallel: bool,
    ) -> Option<NodeRanges> {
        match (self.structure(), parallel) {
            (Structure::Grid(_), _) => None,
            (Structure::CartBvh(b), true) => Some(b.node_ranges(range)),
            (Structure::CartBvh(b), false) => Some(b.node_ranges_sequential(range)),
            (Structure::CylBvh(b), true) => Some(b.node_ranges(range)),
            (Structure::CylBvh(b), false) => Some(b.node_ranges_sequential(range)),
        }
    }

    /// The first `t` of `span` from which the ray may meet a cell that `cell` keeps, within
    /// the nodes whose range (`ranges`, from [`Accel::node_ranges`]) `node` keeps, with the
    /// ray's exit from that piece's bound and the cell; `None` where there is none on the
    /// span, or the ranges were made for another structure.
    pub(crate) fn next_in_ranges(
        &self,
        span: RaySpan,
        ranges: &NodeRanges,
        node: impl Fn([f64; 2]) -> bool,
        cell: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, Option<u32>)> {
        let kept = |i: usize| ranges.get(i).is_some_and(&node);
        self.next_in_nodes(span, ranges.len(), kept, cell, counters)
            .map(|(e, x, c)| (e, x, Some(c)))
    }

    /// The first bound of a piece of a cell that `cell` keeps, within the nodes that `node`
    /// keeps (by their index in the BVH's depth-first order; a node must be kept wherever a
    /// kept cell's piece lies below it). `nodes` is the number of nodes the choice was made
    /// for: `None` unless it is the BVH's, and for a grid.
    fn next_in_nodes(
        &self,
        span: RaySpan,
        nodes: usize,
        node: impl Fn(usize) -> bool,
        cell: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<(f64, f64, u32)> {
        let bvh_nodes = match self.structure() {
            Structure::CartBvh(b) => b.nodes.len(),
            Structure::CylBvh(b) => b.nodes.len(),
            Structure::Grid(_) => return None,
        };
        if nodes != bvh_nodes {
            return None;
        }
        self.first_kept_piece(span, node, cell, counters).flatten()
    }

    /// The closest-hit traversal of the structure's BVH in its own frame, among the nodes
    /// `node(index)` keeps and the pieces of the cells `cell(id)` keeps; `None` for a grid or
    /// a cylindrical BVH without its frame (no bounds to traverse).
    fn first_kept_piece(
        &self,
        span: RaySpan,
        node: impl Fn(usize) -> bool,
        cell: impl Fn(u32) -> bool,
        counters: &mut Counters,
    ) -> Option<Option<(f64, f64, u32)>> {
        match (self.structure(), self.coordinates()) {
            (Structure::CartBvh(b), _) => Some(b.first_kept(span, node, cell, counters)),
            (Structure::CylBvh(b), Coordinates::Cylindrical(frame)) => {
                let tests = self.node_shapes().all();
                Some(b.first_kept_sector((&frame, tests), span, node, cell, counters))
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::NodeShape;
    use crate::accel::grid::GridMask;
    use crate::accel::{AccelParams, StructureKind};
    use crate::datasets::{generate, Dataset};
    use crate::testing::uniform;

    /// Rays from a sphere around a box, one diagonal from its centre, through random points of
    /// the box.
    struct RaysThroughBox {
        lo: DVec3,
        hi: DVec3,
    }

    impl RaysThroughBox {
        /// Around the mesh's box.
        fn of(mesh: &crate::Mesh) -> RaysThroughBox {
            let [x0, x1, y0, y1, z0, z1] = mesh.bounds();
            RaysThroughBox {
                lo: DVec3::new(x0, y0, z0),
                hi: DVec3::new(x1, y1, z1),
            }
        }

        fn centre(&self) -> DVec3 {
            (self.lo + self.hi) * 0.5
        }

        fn diagonal(&self) -> f64 {
            (self.hi - self.lo).length()
        }

        /// A ray's origin and unit direction, from `next`'s uniform numbers.
        fn next(&self, next: &mut impl FnMut() -> f64) -> (DVec3, DVec3) {
            let (u, v) = (2.0 * next() - 1.0, std::f64::consts::TAU * next());
            let w = (1.0 - u * u).sqrt();
            let origin = self.centre() + DVec3::new(w * v.cos(), w * v.sin(), u) * self.diagonal();
            let target = self.lo + (self.hi - self.lo) * DVec3::new(next(), next(), next());
            (origin, (target - origin).normalize())
        }
    }

    /// Skipping never passes a sample the structure locates: along rays from all round the
    /// mesh, through points of its box, the entry [`Accel::next_bound`] gives is at or before
    /// the first of 1,000 samples the structure's point location finds in a cell, and `None`
    /// only where it finds none. For both BVHs over a ring (the rotor) and an O-grid with cells
    /// on the axis (the inlet); the cylindrical BVHs test nodes both as boxes and as sectors.
    /// The entries are also close, so that the skipping is seen to skip: the median distance
    /// from an entry to that first sample is within 2 % of the box's diagonal (entering at the
    /// rays' start, as a skipping that skipped nothing would, the median is about half).
    #[test]
    fn skipping_never_passes_a_located_sample() {
        for dataset in [Dataset::PumpRotor, Dataset::PumpInlet] {
            let mesh = generate(dataset, 3000).expect("mesh");
            let axis = crate::axis::detect(&mesh);
            let rays = RaysThroughBox::of(&mesh);
            let diagonal = rays.diagonal();
            for kind in [StructureKind::CylBvh, StructureKind::CartBvh] {
                let accel =
                    Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("structure");
                if kind == StructureKind::CylBvh {
                    let tests = accel.node_shapes().all();
                    let boxes = tests
                        .iter()
                        .filter(|t| matches!(t, NodeShape::Box(_)))
                        .count();
                    assert!(0 < boxes && boxes < tests.len(), "{dataset:?}: {boxes}");
                }
                let mut next = uniform(7);
                let mut gaps = Vec::new();
                for _ in 0..150 {
                    let (origin, dir) = rays.next(&mut next);
                    let t1 = 2.0 * diagonal;
                    let mut counters = Counters::default();
                    let span = RaySpan {
                        origin,
                        dir,
                        t0: 0.0,
                        t1,
                    };
                    let entry = accel.next_bound(span, &mut counters).map(|s| s.0);
                    let first = (0..1000).map(|k| t1 * k as f64 / 1000.0).find(|&t| {
                        accel
                            .locate(&mesh, origin + dir * t, &mut counters)
                            .is_some()
                    });
                    match (entry, first) {
                        (Some(e), Some(t)) => {
                            assert!(e <= t, "{dataset:?} {kind:?}: entry {e} after {t}");
                            gaps.push((t - e) / diagonal);
                        }
                        (None, Some(t)) => panic!("{dataset:?} {kind:?}: no entry, cell at {t}"),
                        _ => {}
                    }
                }
                assert!(
                    gaps.len() >= 50,
                    "{dataset:?} {kind:?}: {} met the mesh",
                    gaps.len()
                );
                gaps.sort_by(f64::total_cmp);
                let median = gaps[gaps.len() / 2];
                assert!(median <= 0.02, "{dataset:?} {kind:?}: median gap {median}");
            }
        }
    }

    /// A grid's walk never passes a point where the grid offers a kept cell: along rays from
    /// all round the mesh, through points of its box, the answer of
    /// [`Accel::next_marked`] is at or before the first of 2,000 samples whose grid
    /// cell references a kept cell (one in 13 cells kept), and `None` only where no sample's
    /// does. For both grids over a ring (the rotor) and an O-grid with cells on the axis (the
    /// inlet). The walk is seen to walk: on nine rays in ten that meet a kept grid cell it
    /// reaches one (an answer with a hint, a kept cell of that grid cell), within 1 % of the
    /// box's diagonal of the
    /// first such sample at the median; and with nothing kept it answers `None` or stops at
    /// the grid's edge (no hint).
    #[test]
    fn grid_walks_never_pass_a_kept_cell() {
        for dataset in [Dataset::PumpRotor, Dataset::PumpInlet] {
            let mesh = generate(dataset, 3000).expect("mesh");
            let axis = crate::axis::detect(&mesh);
            let rays = RaysThroughBox::of(&mesh);
            let (centre, diagonal) = (rays.centre(), rays.diagonal());
            for kind in [StructureKind::CylGrid, StructureKind::CartGrid] {
                let accel =
                    Accel::build(&mesh, kind, &axis, &AccelParams::default()).expect("structure");
                let Structure::Grid(grid) = accel.structure() else {
                    panic!("{kind:?} is not a grid");
                };
                let keep = |c: u32| c % 13 == 5;
                let mask = accel.mark_cells(keep, true);
                let none = accel.mark_cells(|_| false, false);
                let offered = |p: DVec3| {
                    let q = accel.coordinates().query(p);
                    grid.candidates(q).iter().any(|&c| keep(c))
                };
                let mut next = uniform(11);
                let (mut gaps, mut reached, mut met) = (Vec::new(), 0, 0);
                for _ in 0..150 {
                    let (origin, dir) = rays.next(&mut next);
                    let t1 = 2.0 * diagonal;
                    let mut counters = Counters::default();
                    // From where the ray meets the grid's domain (the walk stops outside it).
                    let t0 = (0..2000)
                        .map(|k| t1 * k as f64 / 2000.0)
                        .find(|&t| {
                            grid.domain()
                                .contains(accel.coordinates().query(origin + dir * t))
                        })
                        .unwrap_or(t1);
                    let span = RaySpan {
                        origin,
                        dir,
                        t0,
                        t1,
                    };
                    let answer = accel.next_marked(span, &mask, keep, &mut counters);
                    let first = (0..2000)
                        .map(|k| t0 + (t1 - t0) * k as f64 / 2000.0)
                        .find(|&t| offered(origin + dir * t));
                    match (answer, first) {
                        (Some((e, x, hint)), Some(t)) => {
                            met += 1;
                            assert!(e <= t, "{dataset:?} {kind:?}: answer {e} after {t}");
                            assert!(e <= x, "{dataset:?} {kind:?}: exit {x} before {e}");
                            if let Some(c) = hint {
                                assert!(keep(c), "{dataset:?} {kind:?}: hint {c}");
                                reached += 1;
                                gaps.push((t - e) / diagonal);
                            }
                        }
                        (None, Some(t)) => {
                            panic!("{dataset:?} {kind:?}: no answer, kept cell offered at {t}")
                        }
                        _ => {}
                    }
                    let empty = accel.next_marked(span, &none, |_| false, &mut counters);
                    assert!(
                        matches!(empty, None | Some((_, _, None))),
                        "{dataset:?} {kind:?}: {empty:?}"
                    );
                }
                // A walk that stalled at a cell's face (an exit computed at the point
                // itself) would stop there, with no hint.
                assert!(
                    reached >= 50 && 10 * reached >= 9 * met,
                    "{dataset:?} {kind:?}: {reached} reached of {met}"
                );
                gaps.sort_by(f64::total_cmp);
                let median = gaps[gaps.len() / 2];
                assert!(median <= 0.01, "{dataset:?} {kind:?}: median gap {median}");
                // A mask of another grid is refused.
                let other = CellMarks::Grid(GridMask::default());
                let span = RaySpan {
                    origin: centre,
                    dir: DVec3::X,
                    t0: 0.0,
                    t1: 1.0,
                };
                let refused = accel.next_marked(span, &other, keep, &mut Counters::default());
                assert_eq!(refused, None);
            }
        }
    }
}
