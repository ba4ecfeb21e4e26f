//! Readers and writers. Each format has its own folder; readers take bytes (so fuzzers and
//! tests need no files) and return a validated [`Mesh`]; [`read_file`] picks the reader from
//! the file name.
//!
//! | format | read | write |
//! |---|---|---|
//! | legacy VTK (`.vtk`), ASCII and BINARY, `UNSTRUCTURED_GRID` and `STRUCTURED_GRID` | [`legacy::read`] | [`legacy::write`] (BINARY unstructured grid) |
//! | VTU (`.vtu`), ascii, base64, raw appended, zlib, LZ4 or LZMA compression, 32/64-bit headers | [`vtu::read`] | [`vtu::write`] (zlib or none) |
//! | parallel VTU (`.pvtu`): an index and one `.vtu` a piece | [`vtu::read_parallel`] | — |
//! | PLOT3D whole single-grid `*xyz.bin` + `*q.bin` | [`plot3d::read`] | — |
//! | VTK image data (`.vti`), one `Float32` array over a 2-D image (a render's depth) | — | [`vti::write_point_scalars`] |

pub mod legacy;
pub mod plot3d;
pub mod structured;
pub mod vti;
pub mod vtu;

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::mesh::Mesh;

/// Options for [`read_file`].
#[derive(Clone, Debug, Default)]
pub struct ReadOptions {
    /// PLOT3D Q (solution) file to use instead of the one found by name beside the grid.
    pub q_file: Option<PathBuf>,
}

/// The formats [`read_file`] recognises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Legacy VTK (`.vtk`).
    LegacyVtk,
    /// VTK XML unstructured grid (`.vtu`).
    Vtu,
    /// VTK XML parallel unstructured grid index (`.pvtu`) and its pieces.
    Pvtu,
    /// PLOT3D grid (`*.bin`, `*.xyz`, `*.x`, `*.g`).
    Plot3d,
}

impl Format {
    /// The format a file name says, by extension.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "vtk" => Some(Format::LegacyVtk),
            "vtu" => Some(Format::Vtu),
            "pvtu" => Some(Format::Pvtu),
            "bin" | "xyz" | "x" | "g" | "p3d" => Some(Format::Plot3d),
            _ => None,
        }
    }
}

/// The Q file that belongs to a PLOT3D grid file by name: `combxyz.bin` → `combq.bin`,
/// `grid.xyz` → `grid.q`, `grid.x` → `grid.q`; `None` when no such file exists.
pub fn plot3d_q_file_for(grid: &Path) -> Option<PathBuf> {
    let name = grid.file_name()?.to_str()?;
    let candidates: Vec<String> = if let Some(i) = name.rfind("xyz") {
        vec![format!("{}q{}", &name[..i], &name[i + 3..])]
    } else {
        let stem = grid.file_stem()?.to_str()?;
        vec![format!("{stem}.q"), format!("{stem}.sol")]
    };
    candidates
        .into_iter()
        .map(|c| grid.with_file_name(c))
        .find(|p| p.is_file())
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    std::fs::read(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads a mesh file, choosing the reader from its extension. Errors name the file.
pub fn read_file(path: &Path, options: &ReadOptions) -> Result<Mesh, Error> {
    let format = Format::from_path(path).ok_or_else(|| {
        Error::Invalid(format!(
            "{}: unknown file type (expected .vtk, .vtu, .pvtu, or a PLOT3D *xyz.bin / .xyz / .x \
             grid)",
            path.display()
        ))
    })?;
    let bytes = read_bytes(path)?;
    match format {
        Format::LegacyVtk => legacy::read(&bytes).map_err(|e| e.in_file(path)),
        Format::Vtu => vtu::read(&bytes).map_err(|e| e.in_file(path)),
        Format::Pvtu => {
            // Pieces are named relative to the index's folder (or absolutely).
            let folder = path.parent().unwrap_or(Path::new(""));
            vtu::read_parallel(&bytes, |source| read_bytes(&folder.join(source)))
                .map_err(|e| e.in_file(path))
        }
        Format::Plot3d => {
            let q_path = match &options.q_file {
                Some(q) => Some(q.clone()),
                None => plot3d_q_file_for(path),
            };
            let q = q_path.as_deref().map(read_bytes).transpose()?;
            plot3d::read(&bytes, q.as_deref()).map_err(|e| e.in_file(path))
        }
    }
}

/// Writes a mesh, choosing the writer from the extension (`.vtk`: legacy binary, `.vtu`).
pub fn write_file(mesh: &Mesh, path: &Path) -> Result<(), Error> {
    let io_err = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io_err)?;
    let mut out = std::io::BufWriter::new(file);
    match Format::from_path(path) {
        Some(Format::LegacyVtk) => legacy::write(mesh, &mut out).map_err(io_err)?,
        Some(Format::Vtu) => vtu::write(mesh, &mut out).map_err(io_err)?,
        _ => {
            return Err(Error::Invalid(format!(
                "{}: can only write .vtk or .vtu",
                path.display()
            )))
        }
    }
    std::io::Write::flush(&mut out).map_err(io_err)
}
