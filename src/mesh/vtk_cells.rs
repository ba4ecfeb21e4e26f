//! Conversion of VTK-style cell arrays (connectivity, offsets, type codes — as `vtkCellArray`
//! and VTU files hold them) into collapsed hexahedra. Readers and the C ABI share it.

use std::collections::BTreeMap;

use super::cell_kind::{
    vtk_type_name, CellKind, VTK_HEXAHEDRON, VTK_PYRAMID, VTK_TETRA, VTK_VOXEL, VTK_WEDGE,
};
use crate::error::MeshError;

/// Cells converted from VTK arrays: collapsed hexahedra and the kind of each.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConvertedCells {
    /// Eight point indices per cell, VTK hexahedron order.
    pub cells: Vec<[u32; 8]>,
    /// The kind of each cell.
    pub kinds: Vec<CellKind>,
}

/// The kind a VTK type code is read as, and the slot order of its VTK vertices.
fn kind_of(code: u8) -> Option<CellKind> {
    match code {
        VTK_HEXAHEDRON | VTK_VOXEL => Some(CellKind::Hexahedron),
        VTK_WEDGE => Some(CellKind::Wedge),
        VTK_PYRAMID => Some(CellKind::Pyramid),
        VTK_TETRA => Some(CellKind::Tetrahedron),
        _ => None,
    }
}

/// Converts one cell given by VTK type code and VTK vertex ids (already checked to be
/// non-negative and below `points`) into a collapsed hexahedron.
fn collapse(code: u8, ids: &[u32]) -> [u32; 8] {
    if code == VTK_VOXEL {
        [
            ids[0], ids[1], ids[3], ids[2], ids[4], ids[5], ids[7], ids[6],
        ]
    } else {
        // Callers only pass supported codes.
        kind_of(code).map_or([0; 8], |k| k.collapse(ids))
    }
}

/// Converts VTK cell arrays into collapsed hexahedra.
///
/// `offsets` has either one entry per cell (the start of each cell, legacy style) or one more
/// (VTK ≥ 9 style, the last being `connectivity.len()`); VTU files give the *end* of each cell,
/// so pass `OffsetStyle::Ends` for them. Unsupported types are counted and reported together;
/// ids are checked against `points`.
///
/// ```
/// use cylvol::mesh::{cells_from_vtk, OffsetStyle};
/// let tet = cells_from_vtk(&[0, 1, 2, 3], &[4], OffsetStyle::Ends, &[10], 4).unwrap();
/// assert_eq!(tet.cells[0], [0, 1, 2, 2, 3, 3, 3, 3]);
/// ```
pub fn cells_from_vtk(
    connectivity: &[i64],
    offsets: &[i64],
    style: OffsetStyle,
    types: &[u8],
    points: usize,
) -> Result<ConvertedCells, MeshError> {
    let n = types.len();
    let ranges = cell_ranges(connectivity.len(), offsets, style, n)?;

    let mut unsupported: BTreeMap<u8, usize> = BTreeMap::new();
    for &code in types {
        if kind_of(code).is_none() {
            *unsupported.entry(code).or_default() += 1;
        }
    }
    if !unsupported.is_empty() {
        return Err(MeshError::UnsupportedCellTypes {
            types: unsupported
                .into_iter()
                .map(|(code, count)| (code, vtk_type_name(code), count))
                .collect(),
        });
    }

    let mut out = ConvertedCells {
        cells: Vec::with_capacity(n),
        kinds: Vec::with_capacity(n),
    };
    let mut ids = [0u32; 8];
    for (cell, (&code, (begin, end))) in types.iter().zip(ranges).enumerate() {
        let kind = kind_of(code).unwrap_or(CellKind::Hexahedron);
        let expected = kind.vertex_count();
        let got = end - begin;
        if got != expected {
            return Err(MeshError::WrongVertexCount {
                cell,
                kind: vtk_type_name(code),
                expected,
                got,
            });
        }
        for (slot, &id) in ids.iter_mut().zip(&connectivity[begin..end]) {
            if id < 0 || id as u64 >= points as u64 || id > u32::MAX as i64 {
                return Err(MeshError::IndexOutOfRange {
                    cell,
                    index: id,
                    points,
                });
            }
            *slot = id as u32;
        }
        out.cells.push(collapse(code, &ids[..got]));
        out.kinds.push(kind);
    }
    Ok(out)
}

/// What the entries of an offsets array mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetStyle {
    /// `offsets[i]` is where cell `i` starts (`vtkCellArray`; may carry one extra final entry).
    Starts,
    /// `offsets[i]` is where cell `i` ends (VTU `offsets`).
    Ends,
}

fn cell_ranges(
    len: usize,
    offsets: &[i64],
    style: OffsetStyle,
    n: usize,
) -> Result<Vec<(usize, usize)>, MeshError> {
    let bounds: Vec<i64> = match style {
        OffsetStyle::Starts if offsets.len() == n + 1 => offsets.to_vec(),
        OffsetStyle::Starts if offsets.len() == n => {
            offsets.iter().copied().chain([len as i64]).collect()
        }
        OffsetStyle::Ends if offsets.len() == n => {
            std::iter::once(0).chain(offsets.iter().copied()).collect()
        }
        _ => {
            return Err(MeshError::CellArrays(format!(
                "{} offsets for {} cell types",
                offsets.len(),
                n
            )))
        }
    };
    let mut ranges = Vec::with_capacity(n);
    for (cell, w) in bounds.windows(2).enumerate() {
        let (b, e) = (w[0], w[1]);
        if b < 0 || e < b || e as u64 > len as u64 {
            return Err(MeshError::CellArrays(format!(
                "cell {cell} spans connectivity [{b}, {e}) of {len} entries"
            )));
        }
        ranges.push((b as usize, e as usize));
    }
    Ok(ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A large array reports its first offender, and a bad span before the ids.
    #[test]
    fn the_first_bad_cell_of_many_is_reported() {
        let n = 100_000;
        let mut connectivity: Vec<i64> = (0..n as i64)
            .flat_map(|c| [c, c + 1, c + 2, c + 3])
            .collect();
        let offsets: Vec<i64> = (1..=n as i64).map(|c| 4 * c).collect();
        let types = vec![VTK_TETRA; n];
        let points = n + 3;
        assert_eq!(
            cells_from_vtk(&connectivity, &offsets, OffsetStyle::Ends, &types, points)
                .unwrap()
                .cells
                .len(),
            n
        );
        for bad in [97_000, 61_000, 30_001] {
            connectivity[4 * bad + 2] = -7;
            match cells_from_vtk(&connectivity, &offsets, OffsetStyle::Ends, &types, points) {
                Err(MeshError::IndexOutOfRange { cell, index, .. }) => {
                    assert_eq!((cell, index), (bad, -7));
                }
                other => panic!("{other:?}"),
            }
        }
        // A bad span before them all comes first, as spans are checked before ids.
        let mut offsets = offsets;
        offsets[80_000] = 3;
        match cells_from_vtk(&connectivity, &offsets, OffsetStyle::Ends, &types, points) {
            Err(MeshError::CellArrays(m)) => assert!(m.starts_with("cell 80000 spans"), "{m}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn voxel_is_reordered_to_hexahedron() {
        let c = cells_from_vtk(
            &[0, 1, 2, 3, 4, 5, 6, 7],
            &[0],
            OffsetStyle::Starts,
            &[11],
            8,
        )
        .unwrap();
        assert_eq!(c.cells[0], [0, 1, 3, 2, 4, 5, 7, 6]);
        assert_eq!(c.kinds[0], CellKind::Hexahedron);
    }

    #[test]
    fn unsupported_types_are_named_and_counted() {
        let err = cells_from_vtk(&[0, 1, 2, 0, 1, 2], &[3, 6], OffsetStyle::Ends, &[5, 5], 3)
            .unwrap_err();
        assert_eq!(
            err,
            MeshError::UnsupportedCellTypes {
                types: vec![(5, "triangle", 2)]
            }
        );
        assert!(err.to_string().contains("2 × triangle"));
    }

    #[test]
    fn out_of_range_and_negative_ids_are_reported() {
        let e = cells_from_vtk(&[0, 1, 2, 9], &[4], OffsetStyle::Ends, &[10], 4).unwrap_err();
        assert!(matches!(e, MeshError::IndexOutOfRange { index: 9, .. }));
        let e = cells_from_vtk(&[0, -1, 2, 3], &[4], OffsetStyle::Ends, &[10], 4).unwrap_err();
        assert!(matches!(e, MeshError::IndexOutOfRange { index: -1, .. }));
    }

    #[test]
    fn bad_offsets_and_counts_are_reported() {
        let e = cells_from_vtk(&[0, 1, 2], &[3], OffsetStyle::Ends, &[10], 4).unwrap_err();
        assert!(matches!(e, MeshError::WrongVertexCount { got: 3, .. }));
        let e = cells_from_vtk(&[0, 1, 2, 3], &[9], OffsetStyle::Ends, &[10], 4).unwrap_err();
        assert!(matches!(e, MeshError::CellArrays(_)));
        let e = cells_from_vtk(&[0, 1, 2, 3], &[], OffsetStyle::Ends, &[10], 4).unwrap_err();
        assert!(matches!(e, MeshError::CellArrays(_)));
    }
}
