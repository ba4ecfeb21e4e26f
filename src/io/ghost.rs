//! VTK's ghost convention, which every VTK reader honours: a `vtkGhostType` cell array of
//! flags marks the cells a parallel writer copied from a neighbouring piece (its ghost layers)
//! and cells hidden by blanking; a `vtkGhostType` point array marks points likewise. The
//! readers that can meet them (VTU, VTS and legacy VTK) drop those cells and both arrays, so a
//! mesh holds each cell once and its arrays are fields, never flags.
//!
//! A structured grid is also blanked by its points, as `vtkStructuredGrid::IsCellVisible`
//! blanks it (and so VTK's triangulation, which its unstructured volume mapper renders): a
//! point flagged hidden hides every cell it is a corner of ([`Blanking::CellsAndPoints`]).
//! An unstructured grid's cells are not hidden by their points in VTK, nor here.

use crate::io::empty::cells_were;
use crate::mesh::{DataArray, MeshParts};

/// The cell flag of VTK's `vtkGhostType` array (`vtkDataSetAttributes`) that marks a cell
/// another piece owns (`DUPLICATECELL`).
const DUPLICATE_CELL: u8 = 1;

/// The cell flag that marks a cell not to be shown (`HIDDENCELL`).
const HIDDEN_CELL: u8 = 32;

/// The point flag of VTK's `vtkGhostType` array that blanks a point (`HIDDENPOINT`).
const HIDDEN_POINT: u8 = 2;

/// The name of VTK's ghost arrays.
const GHOST_ARRAY: &str = "vtkGhostType";

/// What hides a cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Blanking {
    /// Its own flags alone (unstructured grids).
    Cells,
    /// Its own flags, or a hidden corner point (structured grids).
    CellsAndPoints,
}

/// The flags of the one-component `vtkGhostType` array among `arrays`, if it has `tuples`
/// tuples; every ghost array is removed from `arrays` either way (flags, not fields).
fn take_flags(arrays: &mut Vec<DataArray>, tuples: usize) -> Option<Vec<u8>> {
    let flags = arrays
        .iter()
        .find(|a| a.name == GHOST_ARRAY && a.components == 1 && a.values.len() == tuples)
        .map(|a| a.values.iter().map(|&f| f as u8).collect());
    arrays.retain(|a| a.name != GHOST_ARRAY);
    flags
}

/// The cells [`drop_ghost_cells`] dropped, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Dropped {
    /// Copies of another piece's cells (`DUPLICATECELL`).
    pub ghosts: usize,
    /// Cells hidden by blanking (`HIDDENCELL`, or a corner point flagged `HIDDENPOINT`).
    pub hidden: usize,
}

impl Dropped {
    /// How many cells went.
    pub(crate) fn total(self) -> usize {
        self.ghosts + self.hidden
    }

    /// What a user is told of them, a note a reason.
    pub(crate) fn notes(self) -> Vec<String> {
        let mut notes = Vec::new();
        if self.ghosts > 0 {
            notes.push(format!(
                "{} dropped (copies of another piece's cells, flagged in vtkGhostType): each \
                 cell is drawn once",
                cells_were(self.ghosts, "ghost")
            ));
        }
        if self.hidden > 0 {
            notes.push(format!(
                "{} dropped (hidden in vtkGhostType, or with a hidden corner point), as VTK \
                 hides them",
                cells_were(self.hidden, "blanked")
            ));
        }
        notes
    }
}

/// Drops the cells VTK's ghost arrays hide — flagged as another piece's or hidden (a parallel
/// writer's ghost layers, blanked cells), or, with [`Blanking::CellsAndPoints`], with a
/// corner point flagged hidden — and both ghost arrays, which are flags, not fields; says
/// how many cells went, and why. Their points stay (unreferenced). A ghost array of the
/// wrong length hides nothing.
pub(crate) fn drop_ghost_cells(parts: &mut MeshParts, blanking: Blanking) -> Dropped {
    let n_cells = parts.cells.len();
    let point_flags = take_flags(&mut parts.point_data, parts.points.len());
    let cell_flags = take_flags(&mut parts.cell_data, n_cells);
    if parts.kinds.len() != n_cells {
        // Mismatched lengths are the validation's to report; nothing is dropped.
        return Dropped::default();
    }
    let hidden_point = |&p: &u32| {
        point_flags
            .as_ref()
            .filter(|_| blanking == Blanking::CellsAndPoints)
            .and_then(|flags| flags.get(p as usize))
            .is_some_and(|f| f & HIDDEN_POINT != 0)
    };
    let mut dropped = Dropped::default();
    let keep: Vec<bool> = (0..n_cells)
        .map(|c| {
            let flags = cell_flags.as_ref().map_or(0, |f| f[c]);
            if flags & DUPLICATE_CELL != 0 {
                dropped.ghosts += 1;
                false
            } else if flags & HIDDEN_CELL != 0 || parts.cells[c].iter().any(hidden_point) {
                dropped.hidden += 1;
                false
            } else {
                true
            }
        })
        .collect();
    if dropped.total() > 0 {
        drop_cells(parts, &keep);
    }
    dropped
}

/// Keeps the cells `keep` says, with their kinds and cell data tuples.
fn drop_cells(parts: &mut MeshParts, keep: &[bool]) {
    let kept = |i: &usize| keep[*i];
    parts.cells = (0..parts.cells.len())
        .filter(kept)
        .map(|i| parts.cells[i])
        .collect();
    parts.kinds = (0..parts.kinds.len())
        .filter(kept)
        .map(|i| parts.kinds[i])
        .collect();
    for a in &mut parts.cell_data {
        if a.components > 0 && a.values.len() == keep.len() * a.components {
            a.values = a
                .values
                .chunks_exact(a.components)
                .zip(keep)
                .filter(|(_, &k)| k)
                .flat_map(|(v, _)| v.iter().copied())
                .collect();
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::CellKind;

    /// Five cells over distinct ids (cell `i` uses ids `8i..8i + 8`), flagged as `flags` says.
    fn parts(flags: &[f64]) -> MeshParts {
        let n = flags.len();
        MeshParts {
            points: vec![DVec3::ZERO; 8 * n],
            cells: (0..n as u32)
                .map(|i| std::array::from_fn(|k| 8 * i + k as u32))
                .collect(),
            kinds: (0..n)
                .map(|i| {
                    if i % 2 == 0 {
                        CellKind::Hexahedron
                    } else {
                        CellKind::Wedge
                    }
                })
                .collect(),
            point_data: vec![
                DataArray::scalar(GHOST_ARRAY, vec![0.0; 8 * n]),
                DataArray::scalar("p", vec![1.0; 8 * n]),
            ],
            cell_data: vec![
                DataArray::scalar("id", (0..n).map(|i| i as f64).collect()),
                DataArray::scalar(GHOST_ARRAY, flags.to_vec()),
                DataArray {
                    name: "U".into(),
                    components: 3,
                    values: (0..3 * n).map(|v| v as f64).collect(),
                },
            ],
        }
    }

    #[test]
    fn duplicate_and_hidden_cells_go_with_their_tuples_and_both_flag_arrays() {
        // DUPLICATECELL (1), none, HIDDENCELL (32), REFINEDCELL (4, kept), both (33).
        let mut p = parts(&[1.0, 0.0, 32.0, 4.0, 33.0]);
        let before = p.clone();
        assert_eq!(
            drop_ghost_cells(&mut p, Blanking::Cells),
            Dropped {
                ghosts: 2,
                hidden: 1
            }
        );
        assert_eq!(p.cells, [before.cells[1], before.cells[3]]);
        assert_eq!(p.kinds, [CellKind::Wedge, CellKind::Wedge]);
        let names: Vec<&str> = p.cell_data.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["id", "U"]);
        assert_eq!(p.cell_data[0].values, [1.0, 3.0]);
        assert_eq!(p.cell_data[1].values, [3.0, 4.0, 5.0, 9.0, 10.0, 11.0]);
        // Points stay, unreferenced; the point flags go, the fields stay.
        assert_eq!(p.points.len(), before.points.len());
        let names: Vec<&str> = p.point_data.iter().map(|a| a.name.as_str()).collect();
        assert_eq!(names, ["p"]);
    }

    #[test]
    fn unflagged_cells_stay_but_the_flag_arrays_still_go() {
        let mut p = parts(&[0.0, 4.0, 8.0]);
        let before = p.clone();
        assert_eq!(drop_ghost_cells(&mut p, Blanking::Cells).total(), 0);
        assert_eq!((&p.cells, &p.kinds), (&before.cells, &before.kinds));
        assert!(p.cell_data.iter().all(|a| a.name != GHOST_ARRAY));
        assert!(p.point_data.iter().all(|a| a.name != GHOST_ARRAY));
    }

    /// A point flagged hidden (HIDDENPOINT, 2) hides the cells it is a corner of in a
    /// structured grid, not in an unstructured one; a duplicate point (1) hides none.
    #[test]
    fn hidden_points_hide_their_cells_where_points_blank() {
        for (blanking, want) in [
            (Blanking::CellsAndPoints, vec![0.0, 3.0, 4.0]),
            (Blanking::Cells, vec![0.0, 1.0, 3.0, 4.0]),
        ] {
            let mut p = parts(&[0.0, 0.0, 32.0, 0.0, 0.0]);
            p.point_data[0].values[8 + 5] = 2.0; // a corner of cell 1
            p.point_data[0].values[8 * 3 + 2] = 1.0; // a duplicate point of cell 3
            drop_ghost_cells(&mut p, blanking);
            assert_eq!(p.cell_data[0].values, want, "{blanking:?}");
            assert!(p.point_data.iter().all(|a| a.name != GHOST_ARRAY));
        }
    }

    #[test]
    fn a_flag_array_of_the_wrong_length_drops_nothing() {
        let mut p = parts(&[1.0, 1.0, 1.0]);
        p.cell_data[1].values.pop();
        let cells = p.cells.clone();
        assert_eq!(drop_ghost_cells(&mut p, Blanking::Cells).total(), 0);
        assert_eq!(p.cells, cells);
    }
}
