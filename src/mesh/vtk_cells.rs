//! Conversion of VTK-style cell arrays (connectivity, offsets, type codes — as `vtkCellArray`
//! and VTU files hold them) into collapsed hexahedra. Readers and the C ABI share it.

use std::collections::BTreeMap;

use rayon::prelude::*;

use super::cell_kind::{
    vtk_type_name, CellKind, VTK_EMPTY_CELL, VTK_HEXAHEDRON, VTK_PYRAMID, VTK_TETRA, VTK_VOXEL,
    VTK_WEDGE,
};
use crate::error::MeshError;

/// Cells converted from VTK arrays: collapsed hexahedra and the kind of each.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConvertedCells {
    /// Eight point indices per cell, VTK hexahedron order.
    pub cells: Vec<[u32; 8]>,
    /// The kind of each cell.
    pub kinds: Vec<CellKind>,
    /// Where VTK's empty cells ([`VTK_EMPTY_CELL`]: no points, no volume) stood among the
    /// cells given, in increasing order. They are not in `cells`: a reader drops their cell
    /// data tuples too. Always empty from [`cells_from_vtk`], which refuses them.
    pub empty: Vec<usize>,
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
/// so pass `OffsetStyle::Ends` for them. Unsupported types (empty cells included, whose cell
/// data a caller would have to drop with them) are counted and reported together; ids are
/// checked against `points`.
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
    check_types(types, Empty::Refused)?;
    cells_from_ids(
        connectivity.len(),
        |k| connectivity[k],
        offsets,
        style,
        0,
        types,
        points,
    )
}

/// Cells converted (and their kinds written) per parallel task.
const CELLS_PER_TASK: usize = 1 << 14;

/// [`cells_from_vtk`] over a connectivity array of `len` entries read through `id` (entry `k`
/// for `k < len`), so readers convert their stored integers without an `i64` copy of the
/// whole array. Each cell's span of the array begins with `skip` entries that are not ids
/// (1 for the legacy format's classic cell list, where a vertex count leads each cell's ids
/// and the offsets are where each count stands; 0 otherwise). Converts in parallel (the cheap
/// checks of types and spans come first, in one sequential pass each); the error is the one a
/// sequential pass would meet first (unsupported types, then spans, then vertex counts and
/// ids in cell order). Empty cells ([`VTK_EMPTY_CELL`]) are left out and listed in
/// [`ConvertedCells::empty`], whatever ids they list (VTK's `vtkAppendFilter` keeps a blanked
/// cell's ids on the empty cell it makes of it; VTK's readers read them and ignore them).
pub(crate) fn cells_from_ids(
    len: usize,
    id: impl Fn(usize) -> i64 + Sync,
    offsets: &[i64],
    style: OffsetStyle,
    skip: usize,
    types: &[u8],
    points: usize,
) -> Result<ConvertedCells, MeshError> {
    let n = types.len();
    check_types(types, Empty::Dropped)?;
    let bounds = Bounds::new(len, offsets, style, n, skip)?;
    if let Some(cell) = (0..n).find(|&c| bounds.span(c).is_none()) {
        let (b, e) = (bounds.at(cell), bounds.at(cell + 1));
        return Err(MeshError::CellArrays(format!(
            "cell {cell} spans connectivity [{b}, {e}) of {len} entries"
        )));
    }

    let mut out = ConvertedCells {
        cells: vec![[0; 8]; n],
        kinds: vec![CellKind::Hexahedron; n],
        empty: Vec::new(),
    };
    let convert_task = |task: usize, cells: &mut [[u32; 8]], kinds: &mut [CellKind]| {
        let mut ids = [0u32; 8];
        for (j, (cell_out, kind_out)) in cells.iter_mut().zip(kinds).enumerate() {
            let cell = task * CELLS_PER_TASK + j;
            let code = types[cell];
            let kind = kind_of(code).unwrap_or(CellKind::Hexahedron);
            // Checked above.
            if code == VTK_EMPTY_CELL {
                continue;
            }
            let (begin, end) = bounds.span(cell).unwrap_or((0, 0));
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
            for (slot, k) in ids.iter_mut().zip(begin..end) {
                let index = id(k);
                if index < 0 || index as u64 >= points as u64 || index > u32::MAX as i64 {
                    return Err(MeshError::IndexOutOfRange {
                        cell,
                        index,
                        points,
                    });
                }
                *slot = index as u32;
            }
            *cell_out = collapse(code, &ids[..got]);
            *kind_out = kind;
        }
        Ok(())
    };
    let first_error = out
        .cells
        .par_chunks_mut(CELLS_PER_TASK)
        .zip(out.kinds.par_chunks_mut(CELLS_PER_TASK))
        .enumerate()
        .find_map_first(|(task, (cells, kinds))| convert_task(task, cells, kinds).err());
    if let Some(e) = first_error {
        return Err(e);
    }
    out.empty = (0..n).filter(|&c| types[c] == VTK_EMPTY_CELL).collect();
    if !out.empty.is_empty() {
        let keep = |c: &usize| types[*c] != VTK_EMPTY_CELL;
        out.cells = (0..n).filter(keep).map(|c| out.cells[c]).collect();
        out.kinds = (0..n).filter(keep).map(|c| out.kinds[c]).collect();
    }
    Ok(out)
}

/// Whether empty cells ([`VTK_EMPTY_CELL`]) are taken (and dropped) or refused.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Empty {
    Dropped,
    Refused,
}

/// Reports every unsupported type code with its count.
fn check_types(types: &[u8], empty: Empty) -> Result<(), MeshError> {
    let supported =
        |code: u8| kind_of(code).is_some() || (code == VTK_EMPTY_CELL && empty == Empty::Dropped);
    if types.iter().all(|&code| supported(code)) {
        return Ok(());
    }
    let mut unsupported: BTreeMap<u8, usize> = BTreeMap::new();
    for &code in types {
        if !supported(code) {
            *unsupported.entry(code).or_default() += 1;
        }
    }
    Err(MeshError::UnsupportedCellTypes {
        types: unsupported
            .into_iter()
            .map(|(code, count)| (code, vtk_type_name(code), count))
            .collect(),
    })
}

/// What the entries of an offsets array mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetStyle {
    /// `offsets[i]` is where cell `i` starts (`vtkCellArray`; may carry one extra final entry).
    Starts,
    /// `offsets[i]` is where cell `i` ends (VTU `offsets`).
    Ends,
}

/// The cells' boundaries in the connectivity array: boundary `i` is where cell `i` starts
/// and cell `i − 1` ends, for `i` in `0..=n`, whichever [`OffsetStyle`] the offsets have.
#[derive(Clone, Copy)]
struct Bounds<'a> {
    offsets: &'a [i64],
    /// Boundaries before the first offset (1 for ends, whose boundary 0 is implicit).
    lead: usize,
    len: usize,
    /// Entries at the start of each span that are not ids (see [`cells_from_ids`]).
    skip: usize,
}

impl<'a> Bounds<'a> {
    fn new(
        len: usize,
        offsets: &'a [i64],
        style: OffsetStyle,
        n: usize,
        skip: usize,
    ) -> Result<Self, MeshError> {
        let lead = match style {
            OffsetStyle::Starts if offsets.len() == n + 1 || offsets.len() == n => 0,
            OffsetStyle::Ends if offsets.len() == n => 1,
            _ => {
                return Err(MeshError::CellArrays(format!(
                    "{} offsets for {} cell types",
                    offsets.len(),
                    n
                )))
            }
        };
        Ok(Bounds {
            offsets,
            lead,
            len,
            skip,
        })
    }

    /// Boundary `i` (`0` before the offsets, the connectivity's length after them).
    fn at(&self, i: usize) -> i64 {
        match i.checked_sub(self.lead) {
            None => 0,
            Some(k) => self.offsets.get(k).copied().unwrap_or(self.len as i64),
        }
    }

    /// The range of cell `cell`'s ids in the connectivity (its span less the `skip` entries
    /// leading it), `None` when that is not a range within it.
    fn span(&self, cell: usize) -> Option<(usize, usize)> {
        let (start, e) = (self.at(cell), self.at(cell + 1));
        let b = start.checked_add(self.skip as i64)?;
        (start >= 0 && e >= b && e as u64 <= self.len as u64).then_some((b as usize, e as usize))
    }
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

    /// Empty cells are left out and listed by the readers' conversion, with no ids or with
    /// ids (as vtkAppendFilter leaves them), refused by the public one (whose caller has no
    /// way to drop their cell data).
    #[test]
    fn empty_cells_are_dropped_and_listed_or_refused() {
        let connectivity = [0, 1, 2, 3, 1, 2, 3, 4];
        let types = [VTK_TETRA, VTK_EMPTY_CELL, VTK_EMPTY_CELL, VTK_TETRA];
        let ends = [4, 4, 4, 8];
        let id = |k: usize| connectivity[k];
        let c = cells_from_ids(8, id, &ends, OffsetStyle::Ends, 0, &types, 5).unwrap();
        assert_eq!(c.empty, [1, 2]);
        assert_eq!(c.kinds, [CellKind::Tetrahedron; 2]);
        assert_eq!(c.cells[1], CellKind::Tetrahedron.collapse(&[1, 2, 3, 4]));
        match cells_from_vtk(&connectivity, &ends, OffsetStyle::Ends, &types, 5) {
            Err(MeshError::UnsupportedCellTypes { types }) => {
                assert_eq!(types, [(0, "empty cell", 2)])
            }
            other => panic!("{other:?}"),
        }
        let connectivity = [0, 1, 2, 3, 9, 9, 1, 2, 3, 4];
        let ends = [4, 5, 6, 10];
        let id = |k: usize| connectivity[k];
        let with_ids = cells_from_ids(10, id, &ends, OffsetStyle::Ends, 0, &types, 5).unwrap();
        assert_eq!(with_ids, c);
    }

    /// The conversion as a plain sequential loop over the cells, checking types, then spans,
    /// then each cell's vertex count and ids: what the parallel one must equal, result and
    /// first error alike.
    fn sequential(
        connectivity: &[i64],
        offsets: &[i64],
        style: OffsetStyle,
        types: &[u8],
        points: usize,
    ) -> Result<ConvertedCells, MeshError> {
        check_types(types, Empty::Refused)?;
        let n = types.len();
        let bounds: Vec<i64> = match (style, offsets.len()) {
            (OffsetStyle::Starts, l) if l == n + 1 => offsets.to_vec(),
            (OffsetStyle::Starts, l) if l == n => offsets
                .iter()
                .copied()
                .chain([connectivity.len() as i64])
                .collect(),
            (OffsetStyle::Ends, l) if l == n => {
                std::iter::once(0).chain(offsets.to_vec()).collect()
            }
            _ => {
                return Err(MeshError::CellArrays(format!(
                    "{} offsets for {n} cell types",
                    offsets.len()
                )))
            }
        };
        let len = connectivity.len();
        for (cell, w) in bounds.windows(2).enumerate() {
            if w[0] < 0 || w[1] < w[0] || w[1] as u64 > len as u64 {
                return Err(MeshError::CellArrays(format!(
                    "cell {cell} spans connectivity [{}, {}) of {len} entries",
                    w[0], w[1]
                )));
            }
        }
        let mut out = ConvertedCells::default();
        for (cell, (&code, w)) in types.iter().zip(bounds.windows(2)).enumerate() {
            let kind = kind_of(code).unwrap();
            let ids = &connectivity[w[0] as usize..w[1] as usize];
            if ids.len() != kind.vertex_count() {
                return Err(MeshError::WrongVertexCount {
                    cell,
                    kind: vtk_type_name(code),
                    expected: kind.vertex_count(),
                    got: ids.len(),
                });
            }
            if let Some(&index) = ids
                .iter()
                .find(|&&i| i < 0 || i as u64 >= points as u64 || i > u32::MAX as i64)
            {
                return Err(MeshError::IndexOutOfRange {
                    cell,
                    index,
                    points,
                });
            }
            let ids: Vec<u32> = ids.iter().map(|&i| i as u32).collect();
            out.cells.push(collapse(code, &ids));
            out.kinds.push(kind);
        }
        Ok(out)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
        /// Cells of mixed kinds, many parallel tasks' worth, with up to three faults of any
        /// kind planted anywhere (an id out of range, a negative id, a wrong type code, an
        /// offset out of order, a cell one vertex short): the parallel conversion gives what
        /// the sequential loop gives, cells or first error, in both offset styles.
        #[test]
        fn parallel_conversion_equals_the_sequential_loop(
            codes in proptest::collection::vec(
                proptest::sample::select(vec![VTK_HEXAHEDRON, VTK_VOXEL, VTK_WEDGE, VTK_PYRAMID, VTK_TETRA]),
                1..3 * CELLS_PER_TASK,
            ),
            seed in 0u64..u64::MAX,
            faults in proptest::collection::vec((0usize..5, 0.0f64..1.0), 0..4),
        ) {
            let n = codes.len();
            let points = n + 8;
            let mut rng = seed;
            let mut next = move || {
                rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (rng >> 33) as usize
            };
            let mut types = codes;
            let mut connectivity = Vec::new();
            let mut ends = Vec::with_capacity(n);
            for &code in &types {
                let count = kind_of(code).unwrap().vertex_count();
                connectivity.extend((0..count).map(|_| (next() % points) as i64));
                ends.push(connectivity.len() as i64);
            }
            for &(fault, at) in &faults {
                let cell = ((at * n as f64) as usize).min(n - 1);
                match fault {
                    0 => {
                        let k = (at * connectivity.len() as f64) as usize % connectivity.len();
                        connectivity[k] = points as i64 + (next() % 3) as i64;
                    }
                    1 => {
                        let k = (at * connectivity.len() as f64) as usize % connectivity.len();
                        connectivity[k] = -1;
                    }
                    2 => types[cell] = 5,
                    3 => ends[cell] = ends[cell] - 1 - (next() % 20) as i64,
                    _ => {
                        // Cell `cell` loses its last vertex; every later end moves down one.
                        let k = ends[cell] as usize - 1;
                        if ends.iter().all(|&e| e >= 0 && (e as usize) <= connectivity.len()) {
                            connectivity.remove(k);
                            for e in &mut ends[cell..] {
                                *e -= 1;
                            }
                        }
                    }
                }
            }
            let starts: Vec<i64> = std::iter::once(0).chain(ends.iter().copied()).collect();
            for (offsets, style) in [
                (&ends[..], OffsetStyle::Ends),
                (&starts[..], OffsetStyle::Starts),
                (&starts[..n], OffsetStyle::Starts),
            ] {
                let want = sequential(&connectivity, offsets, style, &types, points);
                let got = cells_from_vtk(&connectivity, offsets, style, &types, points);
                proptest::prop_assert_eq!(&got, &want, "{:?}", style);
            }
            if faults.is_empty() {
                proptest::prop_assert!(cells_from_vtk(&connectivity, &ends, OffsetStyle::Ends, &types, points).is_ok());
            }
            // The same cells as a classic legacy list (each cell's vertex count, then its
            // ids) where the spans are well formed, the offsets where each count stands.
            let spans_ok = starts.windows(2).all(|w| 0 <= w[0] && w[0] <= w[1])
                && starts[n] as usize <= connectivity.len();
            if spans_ok {
                let mut list = Vec::new();
                let mut records = Vec::with_capacity(n + 1);
                for w in starts.windows(2) {
                    records.push(list.len() as i64);
                    list.push(w[1] - w[0]);
                    list.extend_from_slice(&connectivity[w[0] as usize..w[1] as usize]);
                }
                records.push(list.len() as i64);
                let want = sequential(&connectivity, &starts, OffsetStyle::Starts, &types, points);
                let got = cells_from_ids(list.len(), |k| list[k], &records, OffsetStyle::Starts, 1, &types, points);
                proptest::prop_assert_eq!(&got, &want, "counted");
            }
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

    /// A span's leading entries are skipped only from a start that is in the array: a
    /// negative start is reported, not moved into it.
    #[test]
    fn skipped_entries_lead_spans_within_the_array() {
        let list = [4i64, 0, 1, 2, 3];
        let tet = [VTK_TETRA];
        let ok = cells_from_ids(5, |k| list[k], &[0, 5], OffsetStyle::Starts, 1, &tet, 4);
        let plain = cells_from_vtk(&[0, 1, 2, 3], &[4], OffsetStyle::Ends, &tet, 4);
        assert_eq!(ok, plain);
        let e = cells_from_ids(5, |k| list[k], &[-1, 5], OffsetStyle::Starts, 1, &tet, 4);
        assert!(matches!(e, Err(MeshError::CellArrays(_))), "{e:?}");
        let e = cells_from_ids(5, |k| list[k], &[5, 5], OffsetStyle::Starts, 1, &tet, 4);
        assert!(matches!(e, Err(MeshError::CellArrays(_))), "{e:?}");
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
