//! Readers and writers. Each format has its own folder; readers take bytes (so fuzzers and
//! tests need no files) and return a validated [`Mesh`]; [`read_file`] picks the reader from
//! the file name.
//!
//! | format | read | write |
//! |---|---|---|
//! | legacy VTK (`.vtk`), ASCII and BINARY, `UNSTRUCTURED_GRID` and `STRUCTURED_GRID` | [`legacy::read`], [`legacy::read_file`] | [`legacy::write`] (BINARY unstructured grid) |
//! | VTU (`.vtu`), ascii, base64, raw appended, zlib, LZ4 or LZMA compression, 32/64-bit headers | [`vtu::read`], [`vtu::read_file`] | [`vtu::write`] (zlib or none) |
//! | parallel VTU (`.pvtu`): an index and one `.vtu` a piece | [`vtu::read_parallel`], [`vtu::read_parallel_file`] | — |
//! | VTK XML structured grid (`.vts`), one or several pieces, blanking | [`vts::read`], [`vts::read_file`] | — |
//! | parallel VTS (`.pvts`): an index and one `.vts` a piece | [`vts::read_parallel_file`] | — |
//! | PLOT3D whole 3-D grids, one or several, `*xyz.bin` + `*q.bin` | [`plot3d::read`], [`plot3d::read_logged`] | — |
//! | VTK image data (`.vti`), one array over a 2-D image (a render's depth) | [`vti::read_point_scalars`] | [`vti::write_point_scalars`] (`Float32`) |

mod elements;
mod empty;
mod ghost;
pub mod legacy;
pub mod plot3d;
pub mod structured;
pub mod vti;
pub mod vts;
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
    /// VTK XML structured grid (`.vts`).
    Vts,
    /// VTK XML parallel structured grid index (`.pvts`) and its pieces.
    Pvts,
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
            "vts" => Some(Format::Vts),
            "pvts" => Some(Format::Pvts),
            "bin" | "xyz" | "x" | "g" | "p3d" => Some(Format::Plot3d),
            _ => None,
        }
    }

    /// What a file of this format is, for messages, unless it is a PLOT3D grid.
    fn not_plot3d(self) -> Option<&'static str> {
        match self {
            Format::LegacyVtk => Some("a legacy VTK file"),
            Format::Vtu => Some("a VTU file"),
            Format::Pvtu => Some("a parallel VTU index"),
            Format::Vts => Some("a VTS file"),
            Format::Pvts => Some("a parallel VTS index"),
            Format::Plot3d => None,
        }
    }
}

/// The Q file that belongs to a PLOT3D grid file by name: `combxyz.bin` → `combq.bin`,
/// `COMBXYZ.BIN` → `COMBQ.BIN`, `grid.xyz` → `grid.q`, `grid.x` → `grid.q` or `grid.sol`;
/// `None` when no such file exists. See [`plot3d_q_names`] for the names tried.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let grid = dir.path().join("COMBXYZ.BIN");
/// std::fs::write(dir.path().join("COMBq.bin"), b"").unwrap();
/// assert_eq!(cylvol::io::plot3d_q_file_for(&grid), Some(dir.path().join("COMBq.bin")));
/// ```
pub fn plot3d_q_file_for(grid: &Path) -> Option<PathBuf> {
    plot3d_q_names(grid).into_iter().find(|p| p.is_file())
}

/// The names a PLOT3D grid's Q file may have beside it, most likely first: the grid's name
/// with its last `xyz` (in any case) replaced by `q`, or else with its extension replaced by
/// `q` or `sol`. The `q` (or `sol`) comes in the case of what it replaces first (`XYZ` → `Q`,
/// `xyz` → `q`), then in the other; the rest of the name after it (`.bin`) as it is, then in
/// lower and upper case; so that `COMBXYZ.BIN` finds `COMBQ.BIN`, and also `COMBq.bin` or
/// `COMBQ.bin`. The part before stays as it is, so no other grid's Q file is taken, and no
/// name that is the grid's own but for case is given.
///
/// ```
/// use std::path::Path;
/// let names = cylvol::io::plot3d_q_names(Path::new("data/combxyz.bin"));
/// assert_eq!(names[0], Path::new("data/combq.bin"));
/// assert_eq!(names[1], Path::new("data/combq.BIN"));
/// assert_eq!(names.len(), 4);
/// assert_eq!(cylvol::io::plot3d_q_names(Path::new("GRID.X"))[0], Path::new("GRID.Q"));
/// ```
pub fn plot3d_q_names(grid: &Path) -> Vec<PathBuf> {
    let Some(name) = grid.file_name().and_then(|n| n.to_str()) else {
        return Vec::new();
    };
    let upper_first = |s: &str| s.starts_with(|c: char| c.is_ascii_uppercase());
    // Each form: the part kept, what replaces the marker (in the marker's case), what follows.
    let mut forms: Vec<(String, String, &str)> = Vec::new();
    if let Some(i) = name.to_ascii_lowercase().rfind("xyz") {
        let q = if upper_first(&name[i..]) { "Q" } else { "q" };
        forms.push((name[..i].to_string(), q.to_string(), &name[i + 3..]));
    } else {
        // As Path::file_stem splits: at the last dot, unless the name starts with it.
        let (stem, extension) = match name.rfind('.').filter(|&d| d > 0) {
            Some(dot) => (&name[..dot], &name[dot + 1..]),
            None => (name, ""),
        };
        for q in ["q", "sol"] {
            let q = if upper_first(extension) {
                q.to_ascii_uppercase()
            } else {
                q.to_string()
            };
            forms.push((format!("{stem}."), q, ""));
        }
    }
    let mut names: Vec<String> = Vec::new();
    for (head, q, tail) in forms {
        let other_q = if upper_first(&q) {
            q.to_ascii_lowercase()
        } else {
            q.to_ascii_uppercase()
        };
        for q in [&q, &other_q] {
            for tail in [
                tail.to_string(),
                tail.to_ascii_lowercase(),
                tail.to_ascii_uppercase(),
            ] {
                let candidate = format!("{head}{q}{tail}");
                if !candidate.eq_ignore_ascii_case(name) && !names.contains(&candidate) {
                    names.push(candidate);
                }
            }
        }
    }
    names.into_iter().map(|n| grid.with_file_name(n)).collect()
}

/// Bytes a parallel task of [`read_bytes`] reads.
const READ_CHUNK: usize = 8 << 20;

/// A whole file's bytes. A regular file larger than one chunk is read in chunks in parallel
/// (positioned reads, on Unix), copying it out of the page cache on every core rather than
/// one. Anything else, or a file whose size changes while it is read, is read with one
/// `std::fs::read`.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_open_file(&file, path)
}

/// [`read_bytes`] of a file already open (`path` names it in errors) whose cursor is at its
/// start, as it is after positioned reads alone: a regular file larger than one chunk by
/// chunks in parallel, anything else (a pipe too) by one read to its end.
pub(crate) fn read_open_file(file: &std::fs::File, path: &Path) -> Result<Vec<u8>, Error> {
    use std::io::Read;
    let io_err = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    #[cfg(unix)]
    if let Some(bytes) = read_in_parallel(file).map_err(io_err)? {
        return Ok(bytes);
    }
    let mut bytes = Vec::new();
    let mut file = file;
    file.read_to_end(&mut bytes).map_err(io_err)?;
    Ok(bytes)
}

/// The file's bytes read by chunks in parallel; `None` when it is not a regular file larger
/// than a chunk, or when it was not read whole (shorter or longer than its size said).
#[cfg(unix)]
fn read_in_parallel(file: &std::fs::File) -> std::io::Result<Option<Vec<u8>>> {
    use std::os::unix::fs::FileExt;

    let meta = file.metadata()?;
    let len = match usize::try_from(meta.len()) {
        Ok(len) if meta.is_file() && len > READ_CHUNK => len,
        _ => return Ok(None),
    };
    let mut bytes = vec![0u8; len];
    let whole = read_exact_at(file, &mut bytes, 0).is_ok();
    let mut beyond = [0u8; 1];
    Ok((whole && file.read_at(&mut beyond, len as u64)? == 0).then_some(bytes))
}

/// Fills `buf` with the file's bytes from `offset`, by chunks of [`READ_CHUNK`] in parallel;
/// an error (`UnexpectedEof` included) if the file does not hold them all.
#[cfg(unix)]
pub(crate) fn read_exact_at(
    file: &std::fs::File,
    buf: &mut [u8],
    offset: u64,
) -> std::io::Result<()> {
    use rayon::prelude::*;
    use std::os::unix::fs::FileExt;

    buf.par_chunks_mut(READ_CHUNK)
        .enumerate()
        .try_for_each(|(i, chunk)| file.read_exact_at(chunk, offset + (i * READ_CHUNK) as u64))
}

/// Reads a mesh file, choosing the reader from its extension. Errors name the file. A Q file
/// in `options` is an error for any file but a PLOT3D grid. Says nothing of what was done
/// beyond reading; [`read_file_logged`] does.
pub fn read_file(path: &Path, options: &ReadOptions) -> Result<Mesh, Error> {
    read_file_logged(path, options, &mut |_| {})
}

/// [`read_file`], giving `log` what a user should know of the read, each note naming its
/// file: cells dropped (empty cells, ghost cells, blanked cells) with how many, bytes after a
/// PLOT3D file's data that were ignored, PLOT3D grids joined into one mesh (see
/// [`plot3d::read_logged`]).
pub fn read_file_logged(
    path: &Path,
    options: &ReadOptions,
    log: &mut dyn FnMut(String),
) -> Result<Mesh, Error> {
    let format = Format::from_path(path).ok_or_else(|| {
        Error::Invalid(format!(
            "{}: unknown file type (expected .vtk, .vtu, .pvtu, .vts, .pvts, or a PLOT3D *xyz.bin \
             / .xyz / .x grid)",
            path.display()
        ))
    })?;
    if let (Some(q), Some(other)) = (&options.q_file, format.not_plot3d()) {
        return Err(Error::Invalid(format!(
            "{}: a PLOT3D Q file goes with a PLOT3D grid, but {} is {other}",
            q.display(),
            path.display()
        )));
    }
    // Each note of a file's reader names the file.
    let mut noting = |note: String| log(format!("{}: {note}", path.display()));
    match format {
        Format::LegacyVtk => legacy::read_file_logged(path, &mut noting),
        Format::Vtu => vtu::read_file_logged(path, &mut noting),
        Format::Pvtu => vtu::read_parallel_file_logged(path, &mut noting),
        Format::Vts => vts::read_file_logged(path, &mut noting),
        Format::Pvts => vts::read_parallel_file_logged(path, &mut noting),
        Format::Plot3d => {
            let bytes = read_bytes(path)?;
            let q_path = match &options.q_file {
                Some(q) => Some(q.clone()),
                None => plot3d_q_file_for(path),
            };
            let q = q_path.as_deref().map(read_bytes).transpose()?;
            let file_of = |kind| match (kind, &q_path) {
                (plot3d::FileKind::Solution, Some(q_path)) => q_path.as_path(),
                _ => path,
            };
            let mut note = |kind, note: String| {
                log(format!("{}: {note}", file_of(kind).display()));
            };
            plot3d::read_blaming(&bytes, q.as_deref(), &mut note)
                .map_err(|(kind, e)| e.in_file(file_of(kind)))
        }
    }
}

/// A mesh writer: [`legacy::write`] or [`vtu::write`].
pub type MeshWriter = fn(&Mesh, &mut dyn std::io::Write) -> std::io::Result<()>;

/// The writer [`write_file`] uses for `path`, by its extension; an error naming the path for
/// any other extension (so that a program can refuse an output before any work).
pub fn writer_for(path: &Path) -> Result<MeshWriter, Error> {
    match Format::from_path(path) {
        Some(Format::LegacyVtk) => Ok(legacy::write),
        Some(Format::Vtu) => Ok(vtu::write),
        _ => Err(Error::Invalid(format!(
            "{}: can only write .vtk or .vtu",
            path.display()
        ))),
    }
}

/// Writes a mesh, choosing the writer from the extension (`.vtk`: legacy binary, `.vtu`).
///
/// Nothing is created for another extension. The mesh is written to a new file beside `path`
/// that replaces it only once written whole, so a write that fails (a full disk) leaves what
/// was at `path` as it was.
///
/// ```
/// use cylvol::datasets::{generate, Dataset};
/// let dir = tempfile::tempdir().unwrap();
/// let mesh = generate(Dataset::PumpRotor, 1000).unwrap();
/// let path = dir.path().join("rotor.vtu");
/// cylvol::io::write_file(&mesh, &path).unwrap();
/// let back = cylvol::io::read_file(&path, &Default::default()).unwrap();
/// assert_eq!(back.cell_count(), mesh.cell_count());
/// // Another extension is refused, and an existing file left alone.
/// let notes = dir.path().join("notes.txt");
/// std::fs::write(&notes, "keep me").unwrap();
/// assert!(cylvol::io::write_file(&mesh, &notes).is_err());
/// assert_eq!(std::fs::read_to_string(&notes).unwrap(), "keep me");
/// ```
pub fn write_file(mesh: &Mesh, path: &Path) -> Result<(), Error> {
    let write = writer_for(path)?;
    write_replacing(path, |partial| {
        let io_err = |source| Error::Io {
            path: partial.to_path_buf(),
            source,
        };
        let mut out = std::io::BufWriter::new(std::fs::File::create(partial).map_err(io_err)?);
        write(mesh, &mut out).map_err(io_err)?;
        std::io::Write::flush(&mut out).map_err(io_err)
    })
}

/// The sibling file a write to `path` goes through, `.NAME.cylvol-PID.partial` in the same
/// folder (hidden, and one per process), or `None` when `path` names no file (`/`, `..`).
///
/// ```
/// use std::path::Path;
/// let partial = cylvol::io::partial_path(Path::new("out/rotor.vtu")).unwrap();
/// assert_eq!(partial.parent(), Some(Path::new("out")));
/// assert!(partial.to_str().unwrap().ends_with(".partial"));
/// assert!(cylvol::io::partial_path(Path::new("/")).is_none());
/// ```
pub fn partial_path(path: &Path) -> Option<PathBuf> {
    let mut partial = std::ffi::OsString::from(".");
    partial.push(path.file_name()?);
    partial.push(format!(".cylvol-{}.partial", std::process::id()));
    Some(path.with_file_name(partial))
}

/// Writes `path` whole or not at all: `write` writes its [`partial_path`], which then replaces
/// `path` by a rename; when anything fails the partial file is removed and what was at `path`
/// is left as it was. Errors name `path`, not the partial file.
///
/// ```
/// use cylvol::Error;
/// let dir = tempfile::tempdir().unwrap();
/// let out = dir.path().join("notes.txt");
/// std::fs::write(&out, "old").unwrap();
/// let failed = cylvol::io::write_replacing(&out, |partial| {
///     std::fs::write(partial, "half").unwrap();
///     Err(Error::Invalid("disk full".into()))
/// });
/// assert!(failed.is_err());
/// assert_eq!(std::fs::read_to_string(&out).unwrap(), "old");
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
/// ```
pub fn write_replacing(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), Error>,
) -> Result<(), Error> {
    let partial = partial_path(path)
        .ok_or_else(|| Error::Invalid(format!("{}: not a file name", path.display())))?;
    let written = write(&partial).and_then(|()| {
        std::fs::rename(&partial, path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })
    });
    if written.is_err() {
        let _ = std::fs::remove_file(&partial);
    }
    written.map_err(|e| match e {
        Error::Io { path: p, source } if p == partial => Error::Io {
            path: path.to_path_buf(),
            source,
        },
        Error::Invalid(m) => {
            Error::Invalid(m.replace(&partial.display().to_string(), &path.display().to_string()))
        }
        e => e,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Files of one chunk or less, of several chunks and a part one, and empty: read whole,
    /// byte for byte; a missing file is an I/O error naming it.
    #[test]
    fn files_are_read_whole_in_parallel_or_not() {
        let dir = tempfile::tempdir().unwrap();
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        for len in [0, 1000, READ_CHUNK, 3 * READ_CHUNK + 12_345] {
            let bytes: Vec<u8> = (0..len)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x as u8
                })
                .collect();
            let path = dir.path().join(format!("f{len}"));
            std::fs::write(&path, &bytes).unwrap();
            let read = read_bytes(&path).unwrap();
            assert!(read == bytes, "{len} bytes");
            #[cfg(unix)]
            assert_eq!(
                read_in_parallel(&std::fs::File::open(&path).unwrap())
                    .unwrap()
                    .is_some(),
                len > READ_CHUNK,
                "{len}"
            );
        }
        let missing = dir.path().join("missing.vtu");
        match read_bytes(&missing) {
            Err(Error::Io { path, .. }) => assert_eq!(path, missing),
            other => panic!("{other:?}"),
        }
    }

    /// Q file names: the `xyz` marker or the extension replaced, its case first, then the
    /// other; what follows as it is, then lower and upper case; never the grid's own name.
    #[test]
    fn plot3d_q_names_keep_the_case_style_first() {
        let names = |grid: &str| -> Vec<String> {
            plot3d_q_names(Path::new(grid))
                .iter()
                .map(|p| p.to_str().unwrap().to_string())
                .collect()
        };
        assert_eq!(
            names("d/COMBXYZ.BIN"),
            ["d/COMBQ.BIN", "d/COMBQ.bin", "d/COMBq.BIN", "d/COMBq.bin"]
        );
        assert_eq!(names("Xyz.Bin")[..2], ["Q.Bin", "Q.bin"]);
        assert_eq!(names("post_xyz_001.bin")[0], "post_q_001.bin");
        assert_eq!(names("xyzxyz.p3d")[0], "xyzq.p3d");
        assert_eq!(
            names("grid.x"),
            ["grid.q", "grid.Q", "grid.sol", "grid.SOL"]
        );
        assert_eq!(
            names("GRID.G"),
            ["GRID.Q", "GRID.q", "GRID.SOL", "GRID.sol"]
        );
        assert_eq!(names("grid"), ["grid.q", "grid.Q", "grid.sol", "grid.SOL"]);
        assert_eq!(names(".x")[0], ".x.q");
        // Not the grid itself, whatever the case (on a file system that ignores it).
        assert_eq!(names("g.q"), ["g.sol", "g.SOL"]);
    }

    /// A legacy file that is not a regular one (a named pipe, as a shell's `<(…)` gives) is
    /// read whole from the one open, ASCII or BINARY, and gives what its bytes give.
    #[cfg(unix)]
    #[test]
    fn legacy_files_are_read_from_pipes() {
        let mesh = crate::datasets::generate(crate::datasets::Dataset::PumpRotor, 1000).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let mut ascii = Vec::new();
        legacy::write_ascii(&mesh, &mut ascii).unwrap();
        let mut binary = Vec::new();
        legacy::write(&mesh, &mut binary).unwrap();
        for (k, bytes) in [ascii, binary].into_iter().enumerate() {
            let want = legacy::read(&bytes).unwrap();
            let pipe = dir.path().join(format!("pipe{k}.vtk"));
            let made = std::process::Command::new("mkfifo")
                .arg(&pipe)
                .status()
                .unwrap();
            assert!(made.success());
            let writer = {
                let pipe = pipe.clone();
                std::thread::spawn(move || std::fs::write(pipe, bytes).unwrap())
            };
            let got = read_file(&pipe, &ReadOptions::default()).unwrap();
            writer.join().unwrap();
            assert_eq!(got, want, "file {k}");
        }
    }
}
