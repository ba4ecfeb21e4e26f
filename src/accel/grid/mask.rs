//! Which grid cells hold a kept cell ([`GridMask`], the grids' counterpart of the BVH's
//! [`crate::accel::bvh::NodeMask`]), and the region of grid cells a point lies in that holds
//! none ([`TwoLevelGrid::masked_cell_at`]): what the fast path's jumps over transparent space
//! walk through on a grid.

use glam::DVec3;
use rayon::prelude::*;

use super::{cell_of, linear, TwoLevelGrid};
use crate::accel::Counters;
use crate::geometry::bounds::Aabb;

/// For every top cell and every leaf cell of a grid, whether it references a kept cell (made
/// by [`TwoLevelGrid::cells_holding`]).
///
/// ```
/// use cylvol::accel::grid::{build_grid, GridParams};
/// use cylvol::accel::space::{Coordinates, Pieces};
/// use cylvol::geometry::bounds::Aabb;
/// use glam::DVec3;
/// // 100 unit boxes along x.
/// let bounds: Vec<Aabb> = (0..100)
///     .map(|i| Aabb::new(DVec3::new(i as f64, 0.0, 0.0), DVec3::new(i as f64 + 1.0, 1.0, 1.0)))
///     .collect();
/// let pieces = Pieces { cells: (0..100).collect(), bounds };
/// let grid = build_grid(Coordinates::Cartesian, &pieces, &GridParams::default());
/// let mask = grid.cells_holding(|cell| cell == 42);
/// assert!(mask.leaf_count() > 0 && mask.leaf_count() < grid.stats().leaf_cells);
/// assert_eq!(grid.cells_holding(|_| false).leaf_count(), 0);
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GridMask {
    top: Vec<bool>,
    leaf: Vec<bool>,
}

impl GridMask {
    /// Whether top cell `t` (linear index, x fastest) references a kept cell in any of its
    /// leaf cells; `false` out of range.
    #[inline]
    pub fn top_holds(&self, t: usize) -> bool {
        self.top.get(t).copied().unwrap_or(false)
    }

    /// Whether leaf cell `l` (index over all the grid's leaf cells) references a kept cell;
    /// `false` out of range.
    #[inline]
    pub fn leaf_holds(&self, l: usize) -> bool {
        self.leaf.get(l).copied().unwrap_or(false)
    }

    /// Whether the mask was made for a grid of this many top and leaf cells.
    pub fn fits(&self, top_cells: usize, leaf_cells: usize) -> bool {
        self.top.len() == top_cells && self.leaf.len() == leaf_cells
    }

    /// The number of leaf cells referencing a kept cell.
    pub fn leaf_count(&self) -> usize {
        self.leaf.iter().filter(|&&h| h).count()
    }
}

/// Where a point lies, for a walk through a grid's cells along a ray
/// ([`TwoLevelGrid::masked_cell_at`]). Regions are boxes in the grid's coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaskedCell {
    /// Outside the grid's domain (or NaN): no cell is there.
    Outside,
    /// In a top cell or a leaf cell (the region given) that references no kept cell.
    Empty(Aabb),
    /// In a leaf cell (its index and region) that references a kept cell.
    Kept(usize, Aabb),
}

impl TwoLevelGrid {
    /// For every grid cell, whether it references a cell that `keep` keeps (in parallel).
    pub fn cells_holding(&self, keep: impl Fn(u32) -> bool + Sync) -> GridMask {
        let leaves = self.leaf_begin.len().saturating_sub(1);
        let leaf: Vec<bool> = (0..leaves)
            .into_par_iter()
            .map(|l| self.leaf_refs(l).iter().any(|&c| keep(c)))
            .collect();
        let top = self.top.par_iter().map(|t| holds(t, &leaf)).collect();
        GridMask { top, leaf }
    }

    /// [`TwoLevelGrid::cells_holding`] on the calling thread only (for a mask made lazily,
    /// whose maker must not wait on work the thread pool might hand back to it).
    pub fn cells_holding_sequential(&self, keep: impl Fn(u32) -> bool) -> GridMask {
        let leaves = self.leaf_begin.len().saturating_sub(1);
        let leaf: Vec<bool> = (0..leaves)
            .map(|l| self.leaf_refs(l).iter().any(|&c| keep(c)))
            .collect();
        let top = self.top.iter().map(|t| holds(t, &leaf)).collect();
        GridMask { top, leaf }
    }

    /// The cell ids leaf cell `l` references (none out of range).
    pub(crate) fn leaf_refs(&self, l: usize) -> &[u32] {
        match (self.leaf_begin.get(l), self.leaf_begin.get(l + 1)) {
            (Some(&b), Some(&e)) => self.refs.get(b as usize..e as usize).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// Where `q` (in the grid's coordinates) lies by `mask`: outside the domain, in a region
    /// holding no kept cell — its whole top cell where the top cell holds none, else its leaf
    /// cell — or in a leaf cell holding one. The point is classified exactly as point location
    /// classifies it ([`TwoLevelGrid::candidates`]); the region is the box of the cell that
    /// classification picks, computed from the same origin and size (a point on a cell's face
    /// may be classified into the neighbour, so the box holds `q` up to rounding). One
    /// internal visit is counted per top cell, one leaf visit per leaf cell.
    pub fn masked_cell_at(&self, q: DVec3, mask: &GridMask, counters: &mut Counters) -> MaskedCell {
        if !self.domain.contains(q) {
            return MaskedCell::Outside;
        }
        let tc = cell_of(q, self.domain.min, self.top_inv, self.top_res);
        let t = linear(tc, self.top_res);
        let Some(top) = self.top.get(t) else {
            return MaskedCell::Outside;
        };
        counters.internal_visits += 1;
        let (origin, inv) = self.leaf_frame(tc, top.res);
        if top.res[0] == 0 || !mask.top_holds(t) {
            return MaskedCell::Empty(Aabb::new(origin, origin + self.top_size));
        }
        counters.leaf_visits += 1;
        let res = top.res.map(u32::from);
        let lc = cell_of(q, origin, inv, res);
        let size = self.top_size / DVec3::new(res[0] as f64, res[1] as f64, res[2] as f64);
        let lo = origin + DVec3::new(lc[0] as f64, lc[1] as f64, lc[2] as f64) * size;
        let region = Aabb::new(lo, lo + size);
        let l = top.first as usize + linear(lc, res);
        if mask.leaf_holds(l) {
            MaskedCell::Kept(l, region)
        } else {
            MaskedCell::Empty(region)
        }
    }
}

/// Whether any of a top cell's leaf cells holds a kept cell by `leaf`.
fn holds(t: &super::TopCell, leaf: &[bool]) -> bool {
    leaf_range(t).any(|l| leaf.get(l).copied().unwrap_or(false))
}

/// The leaf cells of a top cell (none for an empty one).
fn leaf_range(t: &super::TopCell) -> std::ops::Range<usize> {
    let n: usize = t.res.iter().map(|&r| r as usize).product();
    t.first as usize..t.first as usize + n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::grid::{build_grid, GridParams};
    use crate::accel::space::{Coordinates, Pieces};

    fn lattice() -> TwoLevelGrid {
        let mut boxes = Vec::new();
        for k in 0..6 {
            for j in 0..6 {
                for i in 0..6 {
                    let lo = DVec3::new(i as f64, j as f64, k as f64);
                    boxes.push(Aabb::new(lo, lo + DVec3::splat(1.0)));
                }
            }
        }
        let pieces = Pieces {
            cells: (0..boxes.len() as u32).collect(),
            bounds: boxes,
        };
        build_grid(Coordinates::Cartesian, &pieces, &GridParams::default())
    }

    #[test]
    fn masks_agree_with_the_references_and_with_each_other() {
        let grid = lattice();
        let keep = |c: u32| c % 7 == 3;
        let mask = grid.cells_holding(keep);
        assert_eq!(mask, grid.cells_holding_sequential(keep));
        let leaves = grid.stats().leaf_cells;
        assert!(mask.fits(grid.top.len(), leaves));
        for l in 0..leaves {
            assert_eq!(
                mask.leaf_holds(l),
                grid.leaf_refs(l).iter().any(|&c| keep(c))
            );
        }
        for (t, top) in grid.top.iter().enumerate() {
            assert_eq!(
                mask.top_holds(t),
                leaf_range(top).any(|l| mask.leaf_holds(l))
            );
        }
    }

    #[test]
    fn a_point_is_classified_as_point_location_classifies_it() {
        let grid = lattice();
        let keep = |c: u32| c == 100;
        let mask = grid.cells_holding(keep);
        let mut counters = Counters::default();
        let mut kept = 0;
        for n in 0..2000 {
            let f = |k: u32| ((n * k + 7) % 997) as f64 / 997.0 * 6.4 - 0.2;
            let q = DVec3::new(f(13), f(31), f(61));
            let here = grid.candidates(q);
            match grid.masked_cell_at(q, &mask, &mut counters) {
                MaskedCell::Outside => assert!(here.is_empty() && !grid.domain().contains(q)),
                MaskedCell::Empty(region) => {
                    assert!(!here.iter().any(|&c| keep(c)), "{q}");
                    assert!(region.contains(q), "{q} not in {region:?}");
                }
                MaskedCell::Kept(l, region) => {
                    kept += 1;
                    assert!(here.iter().any(|&c| keep(c)));
                    assert_eq!(grid.leaf_refs(l), here);
                    assert_eq!(Some(region), grid.leaf_cell_bounds(q));
                }
            }
        }
        assert!(kept > 0, "no point fell near the kept cell");
    }
}
