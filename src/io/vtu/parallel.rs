//! Parallel VTU files (`.pvtu`): the index VTK's `vtkXMLPUnstructuredGridWriter` (ParaView's
//! "Save Data" from a parallel run, or with several pieces) writes beside one `.vtu` file per
//! piece. The index names the pieces (`<Piece Source="…"/>`) and the active scalars; the
//! pieces are read as any VTU file is, joined in index order, and their ghost cells dropped
//! (a ghost level above 0 repeats each piece's neighbours in it, flagged in `vtkGhostType`).
//! Points the pieces share are repeated, one copy per piece, as VTK's own reader keeps them;
//! the face adjacency welds the faces between pieces by position, as it welds a mesh's seams.
//!
//! The index of a parallel structured grid (`.pvts`, `vtkXMLPStructuredGridWriter`) is read
//! alike, its pieces as `.vts` files ([`crate::io::vts`]).

use rayon::prelude::*;

use super::read::{join_pieces, mesh_with_active, read_parts, FileParts};
use super::xml::{attr, check_file_type, Event, OpenElements, Scanner};
use crate::error::{Error, ReadError};
use crate::Mesh;

/// The datasets a parallel index may hold the pieces of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Indexed {
    /// `PUnstructuredGrid` (`.pvtu`) of `.vtu` pieces.
    UnstructuredGrid,
    /// `PStructuredGrid` (`.pvts`) of `.vts` pieces.
    StructuredGrid,
}

impl Indexed {
    /// The `VTKFile` type and the element that holds the pieces.
    fn element(self) -> &'static str {
        match self {
            Indexed::UnstructuredGrid => "PUnstructuredGrid",
            Indexed::StructuredGrid => "PStructuredGrid",
        }
    }

    /// The format named in index errors.
    fn format(self) -> &'static str {
        match self {
            Indexed::UnstructuredGrid => "parallel VTU",
            Indexed::StructuredGrid => "parallel VTS",
        }
    }

    fn extension(self) -> &'static str {
        match self {
            Indexed::UnstructuredGrid => ".pvtu",
            Indexed::StructuredGrid => ".pvts",
        }
    }
}

/// What an index says: its pieces' file names, in order, and the active scalar it names.
#[derive(Debug, Default, PartialEq)]
struct Index {
    sources: Vec<String>,
    active: Option<String>,
}

/// Parses an index: a `VTKFile` of type `PUnstructuredGrid` (or `PStructuredGrid`) whose
/// element of that name holds one `Piece` with a `Source` per piece.
fn parse_index(bytes: &[u8], kind: Indexed) -> Result<Index, ReadError> {
    let format = kind.format();
    let err = |offset: usize, message: String| ReadError::new(format, offset as u64, message);
    let grid = kind.element();
    let mut sc = Scanner::document(bytes);
    let mut open = OpenElements::new(format);
    let mut index = Index::default();
    let (mut active_point, mut active_cell) = (None, None);
    let mut seen_root = false;
    loop {
        match sc.next_event()? {
            Event::Eof => {
                open.end(bytes)?;
                break;
            }
            Event::Text(range) => open.text(bytes, &range)?,
            Event::End { name, offset } => open.close(name, offset)?,
            Event::Start {
                name,
                attrs,
                empty,
                offset,
                ..
            } => {
                match (open.innermost(), name) {
                    (None, "VTKFile") => {
                        check_file_type(&attrs, grid).map_err(|what| {
                            err(
                                offset,
                                format!(
                                    "the index holds {what}; a {} file indexes the pieces of \
                                     a {grid}",
                                    kind.extension()
                                ),
                            )
                        })?;
                        seen_root = true;
                    }
                    (None, other) => {
                        return Err(err(
                            offset,
                            format!("not a VTK XML file: the root element is <{other}>"),
                        ))
                    }
                    (Some(parent), "PPointData") if parent == grid => {
                        active_point = attr(&attrs, "Scalars").map(str::to_string);
                    }
                    (Some(parent), "PCellData") if parent == grid => {
                        active_cell = attr(&attrs, "Scalars").map(str::to_string);
                    }
                    (Some(parent), "Piece") if parent == grid => {
                        let source = attr(&attrs, "Source")
                            .filter(|s| !s.trim().is_empty())
                            .ok_or_else(|| err(offset, "<Piece> has no Source file".into()))?;
                        index.sources.push(source.trim().to_string());
                    }
                    _ => {}
                }
                if !empty {
                    open.open(name);
                }
            }
        }
    }
    if !seen_root {
        return Err(err(0, "not a VTK XML file: no <VTKFile> element".into()));
    }
    if index.sources.is_empty() {
        return Err(err(
            0,
            "the index names no piece (<Piece Source=\"…\"/>)".into(),
        ));
    }
    index.active = active_point
        .map(|n| format!("point:{n}"))
        .or_else(|| active_cell.map(|n| format!("cell:{n}")));
    Ok(index)
}

/// Reads a parallel VTU index and its pieces into one validated mesh. `load` gives the bytes
/// of a piece from its `Source` name as the index writes it (relative to the index's folder,
/// for files; [`crate::io::read_file`] resolves it so). Pieces are read in parallel and
/// joined in index order; an error in a piece names its source.
///
/// ```
/// use cylvol::datasets::{generate, Dataset};
/// use cylvol::io::vtu;
/// let mesh = generate(Dataset::PumpInlet, 1000).unwrap();
/// let mut piece = Vec::new();
/// vtu::write(&mesh, &mut piece).unwrap();
/// let index = br#"<VTKFile type="PUnstructuredGrid"><PUnstructuredGrid>
///   <Piece Source="a.vtu"/><Piece Source="b.vtu"/></PUnstructuredGrid></VTKFile>"#;
/// // The same piece twice: twice the cells.
/// let both = vtu::read_parallel(index, |_| Ok(piece.clone())).unwrap();
/// assert_eq!(both.cell_count(), 2 * mesh.cell_count());
/// ```
pub fn read_parallel(
    index: &[u8],
    load: impl Fn(&str) -> Result<Vec<u8>, Error> + Sync,
) -> Result<Mesh, Error> {
    let read_piece = |source: &str| {
        let bytes = load(source)?;
        read_parts(&bytes).map_err(|e| e.in_file(source))
    };
    read_index_with(index, Indexed::UnstructuredGrid, read_piece, &mut |_| {})
}

/// Reads an index of `kind`, each piece's parts (with the active scalar it names, and its
/// notes) from `read_piece`, given the piece's `Source`: the pieces read in parallel, joined
/// in index order; `log` is given every piece's notes, each naming its piece.
pub(crate) fn read_index_with(
    index: &[u8],
    kind: Indexed,
    read_piece: impl Fn(&str) -> Result<FileParts, Error> + Sync,
    log: &mut dyn FnMut(String),
) -> Result<Mesh, Error> {
    let index = parse_index(index, kind)?;
    let pieces: Vec<FileParts> = index
        .sources
        .par_iter()
        .map(|source| read_piece(source))
        .collect::<Result<_, _>>()?;
    let active = index
        .active
        .or_else(|| pieces.iter().find_map(|p| p.active.clone()));
    let mut all_parts = Vec::with_capacity(pieces.len());
    for (piece, source) in pieces.into_iter().zip(&index.sources) {
        for note in piece.notes {
            log(format!("{source}: {note}"));
        }
        all_parts.push(piece.parts);
    }
    let parts = join_pieces(all_parts).map_err(|m| ReadError::new(kind.format(), 0, m))?;
    mesh_with_active(parts, active.as_deref())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_index_gives_sources_and_scalars() {
        let index = br#"<?xml version="1.0"?>
<VTKFile type="PUnstructuredGrid" version="0.1">
  <PUnstructuredGrid GhostLevel="1">
    <PPointData Scalars="p"><PDataArray type="Float32" Name="p"/></PPointData>
    <PCellData Scalars="c"/>
    <PPoints><PDataArray type="Float32" NumberOfComponents="3"/></PPoints>
    <Piece Source="run_0.vtu"/>
    <Piece Source=" sub/run_1.vtu "/>
  </PUnstructuredGrid>
</VTKFile>"#;
        let parsed = parse_index(index, Indexed::UnstructuredGrid).unwrap();
        assert_eq!(parsed.sources, ["run_0.vtu", "sub/run_1.vtu"]);
        assert_eq!(parsed.active.as_deref(), Some("point:p"));
    }

    #[test]
    fn bad_indices_are_named() {
        for (bytes, needle) in [
            (
                &br#"<VTKFile type="UnstructuredGrid"><UnstructuredGrid/></VTKFile>"#[..],
                "a UnstructuredGrid dataset",
            ),
            (
                br#"<VTKFile type="PUnstructuredGrid"><PUnstructuredGrid/></VTKFile>"#,
                "names no piece",
            ),
            (
                br#"<VTKFile type="PUnstructuredGrid"><PUnstructuredGrid><Piece/></PUnstructuredGrid></VTKFile>"#,
                "no Source",
            ),
            (
                br#"<VTKFile type="PUnstructuredGrid"><PUnstructuredGrid>"#,
                "ends inside",
            ),
            (b"<Foo/>", "<Foo>"),
            (b"", "no <VTKFile>"),
        ] {
            let e = parse_index(bytes, Indexed::UnstructuredGrid).unwrap_err();
            assert!(e.message.contains(needle), "{needle}: {e}");
        }
    }
}
