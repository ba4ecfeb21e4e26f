//! Point location: the leaf cell holding a point, and its candidate cells.

use glam::DVec3;

use super::{cell_of, linear, TwoLevelGrid};
use crate::accel::Counters;
use crate::geometry::bounds::Aabb;

impl TwoLevelGrid {
    /// The leaf cell holding `q` (in the grid's coordinates), counting the top and leaf cells
    /// visited; `None`, with no work counted, outside the domain or in an empty top cell
    /// (the top cell is then counted).
    #[inline]
    fn leaf_of(&self, q: DVec3, counters: &mut Counters) -> Option<usize> {
        if !self.domain.contains(q) {
            return None;
        }
        let tc = cell_of(q, self.domain.min, self.top_inv, self.top_res);
        let top = self.top.get(linear(tc, self.top_res))?;
        counters.internal_visits += 1;
        if top.res[0] == 0 {
            return None;
        }
        let (origin, inv) = self.leaf_frame(tc, top.res);
        let res = top.res.map(u32::from);
        counters.leaf_visits += 1;
        Some(top.first as usize + linear(cell_of(q, origin, inv, res), res))
    }

    /// The candidate cells for `q` (in the grid's coordinates): the distinct ids of the cells
    /// whose pieces overlap the leaf cell holding `q` (empty outside the domain), in the
    /// build's [`super::CandidateOrder`].
    pub fn candidates(&self, q: DVec3) -> &[u32] {
        let mut counters = Counters::default();
        self.candidates_counted(q, &mut counters)
    }

    #[inline]
    fn candidates_counted(&self, q: DVec3, counters: &mut Counters) -> &[u32] {
        let Some(leaf) = self.leaf_of(q, counters) else {
            return &[];
        };
        let (Some(&b), Some(&e)) = (self.leaf_begin.get(leaf), self.leaf_begin.get(leaf + 1))
        else {
            return &[];
        };
        self.refs.get(b as usize..e as usize).unwrap_or(&[])
    }

    /// Offers the candidate cells for `q` (a point already in the grid's coordinates, see
    /// [`crate::accel::Coordinates::of`]) to `accept`, in order, until it returns `true`;
    /// returns that cell, or `None`. Counts one internal visit per top cell and one leaf visit
    /// per second-level cell visited; a point outside the domain costs nothing.
    #[inline]
    pub fn find(
        &self,
        q: DVec3,
        counters: &mut Counters,
        mut accept: impl FnMut(u32) -> bool,
    ) -> Option<u32> {
        self.candidates_counted(q, counters)
            .iter()
            .copied()
            .find(|&c| accept(c))
    }

    /// The box, in the grid's coordinates, of the leaf cell holding `q` (`None` outside the
    /// domain or in an empty top cell). For tests and diagnostics.
    pub fn leaf_cell_bounds(&self, q: DVec3) -> Option<Aabb> {
        if !self.domain.contains(q) {
            return None;
        }
        let tc = cell_of(q, self.domain.min, self.top_inv, self.top_res);
        let top = self.top.get(linear(tc, self.top_res))?;
        if top.res[0] == 0 {
            return None;
        }
        let (origin, inv) = self.leaf_frame(tc, top.res);
        let res = top.res.map(u32::from);
        let lc = cell_of(q, origin, inv, res);
        let size = self.top_size / DVec3::new(res[0] as f64, res[1] as f64, res[2] as f64);
        let lo = DVec3::new(lc[0] as f64, lc[1] as f64, lc[2] as f64);
        Some(Aabb::new(
            origin + lo * size,
            origin + (lo + DVec3::ONE) * size,
        ))
    }
}
