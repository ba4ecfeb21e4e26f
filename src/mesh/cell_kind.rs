//! The cell kinds cylvol renders and how each is stored as a (possibly collapsed) hexahedron.
//!
//! Every cell is eight point indices in VTK's hexahedron order, so one trilinear code path serves
//! all kinds. The other kinds repeat vertices; with VTK's own vertex numbering of each kind:
//!
//! | kind | VTK type | VTK vertices | stored as hexahedron `[h0 … h7]` |
//! |---|---|---|---|
//! | hexahedron | 12 | 0…7 | `[0, 1, 2, 3, 4, 5, 6, 7]` |
//! | voxel (read as a hexahedron) | 11 | 0…7, x fastest | `[0, 1, 3, 2, 4, 5, 7, 6]` |
//! | wedge | 13 | 0…5 | `[0, 2, 1, 1, 3, 5, 4, 4]` |
//! | pyramid | 14 | 0…4 | `[0, 1, 2, 3, 4, 4, 4, 4]` |
//! | tetrahedron | 10 | 0…3 | `[0, 1, 2, 2, 3, 3, 3, 3]` |
//!
//! A cell VTK calls well formed (`vtkCellValidator`) has a non-negative Jacobian everywhere as
//! stored (zero only on the collapsed edges and faces): VTK's hexahedron, pyramid and
//! tetrahedron number their base so that its normal by the right-hand rule points into the
//! cell, but its wedge numbers the base triangle `0, 1, 2` so that its normal points *out*
//! (away from `3, 4, 5`), so the wedge's base enters the hexahedron's in reverse.

use std::fmt;

/// The kind of a cell, as given in the input. Storage is always a collapsed hexahedron.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CellKind {
    /// An eight-vertex hexahedron (VTK 12, or a VTK 11 voxel reordered).
    Hexahedron,
    /// A six-vertex wedge, or triangular prism (VTK 13).
    Wedge,
    /// A five-vertex pyramid (VTK 14).
    Pyramid,
    /// A four-vertex tetrahedron (VTK 10).
    Tetrahedron,
}

/// VTK cell type code of a hexahedron.
pub const VTK_HEXAHEDRON: u8 = 12;
/// VTK cell type code of a voxel (an axis-aligned hexahedron with x-fastest vertex order).
pub const VTK_VOXEL: u8 = 11;
/// VTK cell type code of a wedge.
pub const VTK_WEDGE: u8 = 13;
/// VTK cell type code of a pyramid.
pub const VTK_PYRAMID: u8 = 14;
/// VTK cell type code of a tetrahedron.
pub const VTK_TETRA: u8 = 10;
/// VTK cell type code of an empty cell: no points, no volume. VTK writes them where the
/// blanked cells of a structured grid become an unstructured grid's (`vtkAppendFilter`,
/// ParaView's Merge Blocks).
pub const VTK_EMPTY_CELL: u8 = 0;

impl CellKind {
    /// All kinds, in the order reports list them.
    pub const ALL: [CellKind; 4] = [
        CellKind::Hexahedron,
        CellKind::Wedge,
        CellKind::Pyramid,
        CellKind::Tetrahedron,
    ];

    /// The name used in reports and JSON: `hexahedron`, `wedge`, `pyramid`, `tetrahedron`.
    pub fn name(self) -> &'static str {
        match self {
            CellKind::Hexahedron => "hexahedron",
            CellKind::Wedge => "wedge",
            CellKind::Pyramid => "pyramid",
            CellKind::Tetrahedron => "tetrahedron",
        }
    }

    /// The VTK cell type code writers use for this kind.
    pub fn vtk_type(self) -> u8 {
        match self {
            CellKind::Hexahedron => VTK_HEXAHEDRON,
            CellKind::Wedge => VTK_WEDGE,
            CellKind::Pyramid => VTK_PYRAMID,
            CellKind::Tetrahedron => VTK_TETRA,
        }
    }

    /// Number of distinct vertices of this kind in VTK.
    pub fn vertex_count(self) -> usize {
        match self {
            CellKind::Hexahedron => 8,
            CellKind::Wedge => 6,
            CellKind::Pyramid => 5,
            CellKind::Tetrahedron => 4,
        }
    }

    /// For each hexahedron slot, the VTK vertex of this kind stored there (see the module table).
    pub fn hex_slots(self) -> [usize; 8] {
        match self {
            CellKind::Hexahedron => [0, 1, 2, 3, 4, 5, 6, 7],
            CellKind::Wedge => [0, 2, 1, 1, 3, 5, 4, 4],
            CellKind::Pyramid => [0, 1, 2, 3, 4, 4, 4, 4],
            CellKind::Tetrahedron => [0, 1, 2, 2, 3, 3, 3, 3],
        }
    }

    /// For each VTK vertex of this kind, the hexahedron slot it is read back from.
    pub fn vtk_slots(self) -> &'static [usize] {
        match self {
            CellKind::Hexahedron => &[0, 1, 2, 3, 4, 5, 6, 7],
            CellKind::Wedge => &[0, 2, 1, 4, 6, 5],
            CellKind::Pyramid => &[0, 1, 2, 3, 4],
            CellKind::Tetrahedron => &[0, 1, 2, 4],
        }
    }

    /// The collapsed-hexahedron form of a cell given by its VTK vertex ids of this kind.
    ///
    /// ```
    /// use cylvol::CellKind;
    /// assert_eq!(CellKind::Tetrahedron.collapse(&[7, 8, 9, 10]), [7, 8, 9, 9, 10, 10, 10, 10]);
    /// ```
    pub fn collapse(self, vtk_ids: &[u32]) -> [u32; 8] {
        self.hex_slots().map(|slot| vtk_ids[slot])
    }

    /// The VTK vertex ids of a stored cell of this kind (inverse of [`CellKind::collapse`]).
    ///
    /// ```
    /// use cylvol::CellKind;
    /// let hex = CellKind::Wedge.collapse(&[1, 2, 3, 4, 5, 6]);
    /// assert_eq!(CellKind::Wedge.expand(&hex), vec![1, 2, 3, 4, 5, 6]);
    /// ```
    pub fn expand(self, hex: &[u32; 8]) -> Vec<u32> {
        self.vtk_slots().iter().map(|&slot| hex[slot]).collect()
    }
}

impl fmt::Display for CellKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The name of a VTK cell type code, for error messages (`"VTK type 99"` style names for
/// codes VTK does not define are given as `"unknown"`).
pub fn vtk_type_name(code: u8) -> &'static str {
    match code {
        0 => "empty cell",
        1 => "vertex",
        2 => "poly-vertex",
        3 => "line",
        4 => "poly-line",
        5 => "triangle",
        6 => "triangle strip",
        7 => "polygon",
        8 => "pixel",
        9 => "quad",
        10 => "tetrahedron",
        11 => "voxel",
        12 => "hexahedron",
        13 => "wedge",
        14 => "pyramid",
        15 => "pentagonal prism",
        16 => "hexagonal prism",
        21 => "quadratic edge",
        22 => "quadratic triangle",
        23 => "quadratic quad",
        24 => "quadratic tetrahedron",
        25 => "quadratic hexahedron",
        26 => "quadratic wedge",
        27 => "quadratic pyramid",
        29 => "triquadratic hexahedron",
        42 => "polyhedron",
        _ => "unknown",
    }
}
