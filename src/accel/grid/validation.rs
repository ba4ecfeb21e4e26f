//! Structural checks of a built grid against the pieces it was built from, for tests.

use std::collections::HashMap;

use rayon::prelude::*;

use super::{cell_of, linear, TwoLevelGrid};
use crate::accel::space::Pieces;
use crate::geometry::bounds::Aabb;

impl TwoLevelGrid {
    /// Panics with a clear message unless the grid is well formed for `pieces`:
    /// - the arrays are consistent: one top cell per top-level index, leaf cells laid out per
    ///   top cell without gaps, monotone ranges ending at the number of references, and the
    ///   references of each leaf cell distinct;
    /// - every valid piece is referenced (by its cell id) in every leaf cell its box overlaps,
    ///   and its box lies in the domain;
    /// - every reference in a leaf cell belongs to a piece whose box overlaps that leaf cell.
    ///
    /// "Overlaps" is in cell-index space, with the same cell function the query uses (so it is
    /// exactly what the query relies on, rounding included).
    /// Costs about as much as a build; meant for tests.
    pub fn assert_well_formed(&self, pieces: &Pieces<Aabb>) {
        let valid = |b: &Aabb| !b.is_empty() && b.min.is_finite() && b.max.is_finite();
        let n = pieces.bounds.len().min(pieces.cells.len());
        let top_cells: usize = self.top_res.iter().map(|&r| r as usize).product();
        if self.domain.is_empty() {
            assert!(
                pieces.bounds.iter().all(|b| !valid(b)),
                "grid: empty domain but some piece has a valid box"
            );
            assert!(self.refs.is_empty(), "grid: empty domain with references");
            return;
        }
        assert_eq!(
            self.top.len(),
            top_cells,
            "grid: top cells ≠ product of top resolution"
        );
        let mut next = 0u64;
        for (t, tc) in self.top.iter().enumerate() {
            let empty = tc.res.contains(&0);
            assert!(
                !empty || tc.res == [0; 3],
                "grid: top cell {t} has a partly zero resolution {:?}",
                tc.res
            );
            assert_eq!(
                tc.first as u64, next,
                "grid: top cell {t} leaf cells not contiguous"
            );
            next += tc.res.iter().map(|&r| r as u64).product::<u64>() * u64::from(!empty);
        }
        assert_eq!(
            self.leaf_begin.len() as u64,
            next + 1,
            "grid: leaf range array has the wrong length"
        );
        assert!(
            self.leaf_begin.windows(2).all(|w| w[0] <= w[1]),
            "grid: leaf ranges not monotone"
        );
        assert_eq!(
            self.leaf_begin.first(),
            Some(&0),
            "grid: first range does not start at 0"
        );
        assert_eq!(
            self.leaf_begin.last().map(|&e| e as usize),
            Some(self.refs.len()),
            "grid: last range does not end at the references' end"
        );
        let leaf_refs =
            |l: usize| &self.refs[self.leaf_begin[l] as usize..self.leaf_begin[l + 1] as usize];
        (0..next as usize).into_par_iter().for_each(|l| {
            assert!(
                {
                    let mut ids = leaf_refs(l).to_vec();
                    ids.sort_unstable();
                    ids.windows(2).all(|w| w[0] < w[1])
                },
                "grid: leaf cell {l} references are not distinct: {:?}",
                leaf_refs(l)
            );
        });

        // Leaf ranges of a piece's box: (leaf cell id) for each leaf cell it overlaps.
        let leaf_cells_of = |b: &Aabb, f: &mut dyn FnMut(usize, usize)| {
            let lo = cell_of(b.min, self.domain.min, self.top_inv, self.top_res);
            let hi = cell_of(b.max, self.domain.min, self.top_inv, self.top_res);
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let t = linear([x, y, z], self.top_res);
                        let tc = self.top[t];
                        assert!(tc.res[0] > 0, "grid: a piece overlaps empty top cell {t}");
                        let (origin, inv) = self.leaf_frame([x, y, z], tc.res);
                        let res = tc.res.map(u32::from);
                        let llo = cell_of(b.min, origin, inv, res);
                        let lhi = cell_of(b.max, origin, inv, res);
                        for lz in llo[2]..=lhi[2] {
                            for ly in llo[1]..=lhi[1] {
                                for lx in llo[0]..=lhi[0] {
                                    f(t, tc.first as usize + linear([lx, ly, lz], res));
                                }
                            }
                        }
                    }
                }
            }
        };

        // Every piece in every leaf cell it overlaps.
        (0..n).into_par_iter().for_each(|i| {
            let b = &pieces.bounds[i];
            if !valid(b) {
                return;
            }
            assert!(
                self.domain.contains(b.min) && self.domain.contains(b.max),
                "grid: piece {i} box {b:?} is not inside the domain {:?}",
                self.domain
            );
            let cell = pieces.cells[i];
            leaf_cells_of(b, &mut |t, l| {
                assert!(
                    leaf_refs(l).contains(&cell),
                    "grid: piece {i} (cell {cell}) overlaps leaf cell {l} of top cell {t} but is not referenced there"
                );
            });
        });

        // Every reference backed by a piece overlapping its leaf cell: count, per leaf cell and
        // cell id, the overlaps the pieces make, and compare with the references.
        let mut backed: HashMap<(usize, u32), ()> = HashMap::new();
        for i in 0..n {
            let b = &pieces.bounds[i];
            if valid(b) {
                leaf_cells_of(b, &mut |_, l| {
                    backed.insert((l, pieces.cells[i]), ());
                });
            }
        }
        for l in 0..next as usize {
            for &c in leaf_refs(l) {
                assert!(
                    backed.contains_key(&(l, c)),
                    "grid: leaf cell {l} references cell {c}, but no piece of that cell overlaps it"
                );
            }
        }
        assert_eq!(
            backed.len(),
            self.refs.len(),
            "grid: references ≠ distinct (leaf cell, cell) overlaps"
        );
    }
}
