//! Typed errors. Every failure a user can cause — a bad file, a bad mesh, a bad argument — is one
//! of these, with a message that says what and where; nothing in the library panics on input.

use std::path::PathBuf;

use crate::mesh::data::Association;

/// Any error cylvol reports.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An operating-system error on a named file.
    #[error("{path}: {source}")]
    Io {
        /// The file involved.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// A file's content could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The mesh (from a file, a dataset or caller arrays) is not usable.
    #[error("invalid mesh: {0}")]
    Mesh(#[from] MeshError),
    /// An error while handling a named file: the path, then the error.
    #[error("{path}: {source}")]
    InFile {
        /// The file involved.
        path: PathBuf,
        /// What went wrong in it.
        source: Box<Error>,
    },
    /// A request that cannot be carried out as asked (an unknown dataset name, a bad option).
    #[error("{0}")]
    Invalid(String),
}

impl Error {
    /// Wraps this error with the path of the file it concerns.
    pub fn in_file(self, path: impl Into<PathBuf>) -> Error {
        Error::InFile {
            path: path.into(),
            source: Box::new(self),
        }
    }
}

/// A file that could not be parsed: the format, where in the file, and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{format}: {message} (at byte {offset}{})", line.map(|l| format!(", line {l}")).unwrap_or_default())]
pub struct ReadError {
    /// The format being read, e.g. `"legacy VTK"`, `"VTU"`, `"PLOT3D"`.
    pub format: &'static str,
    /// Byte offset in the file where the problem was found.
    pub offset: u64,
    /// Line number (1-based) for text formats, where known.
    pub line: Option<usize>,
    /// What was wrong.
    pub message: String,
}

impl ReadError {
    /// A new read error at a byte offset.
    pub fn new(format: &'static str, offset: u64, message: impl Into<String>) -> ReadError {
        ReadError {
            format,
            offset,
            line: None,
            message: message.into(),
        }
    }

    /// The same error with a line number.
    pub fn at_line(mut self, line: usize) -> ReadError {
        self.line = Some(line);
        self
    }
}

/// Why a mesh is not usable. Produced by [`crate::Mesh::from_parts`] and the VTK cell-array
/// conversion, whatever the mesh came from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// No points or no cells.
    #[error("the mesh is empty ({points} points, {cells} cells)")]
    Empty {
        /// Number of points.
        points: usize,
        /// Number of cells.
        cells: usize,
    },
    /// A point coordinate is NaN or infinite.
    #[error("point {index} has a non-finite coordinate {coordinates:?}")]
    NonFinitePoint {
        /// Index of the first such point.
        index: usize,
        /// Its coordinates.
        coordinates: [f64; 3],
    },
    /// A cell refers to a point that does not exist.
    #[error("cell {cell} refers to point {index}, but the mesh has {points} points")]
    IndexOutOfRange {
        /// Index of the first such cell.
        cell: usize,
        /// The offending point index (as given, possibly negative).
        index: i64,
        /// Number of points.
        points: usize,
    },
    /// Cells of types cylvol cannot render.
    #[error("unsupported cell types: {}", list_types(.types))]
    UnsupportedCellTypes {
        /// `(VTK type code, type name, number of cells)` for each unsupported type.
        types: Vec<(u8, &'static str, usize)>,
    },
    /// A cell has the wrong number of vertices for its type.
    #[error("cell {cell} is a {kind} but has {got} vertices (expected {expected})")]
    WrongVertexCount {
        /// Index of the cell.
        cell: usize,
        /// Its type name.
        kind: &'static str,
        /// Vertices a cell of that type has.
        expected: usize,
        /// Vertices given.
        got: usize,
    },
    /// Connectivity, offsets and types arrays disagree.
    #[error("inconsistent cell arrays: {0}")]
    CellArrays(String),
    /// A data array has the wrong number of values.
    #[error("{association} array '{name}' has {got} values, expected {expected}")]
    ArrayLength {
        /// Array name.
        name: String,
        /// Point or cell data.
        association: Association,
        /// `tuples × components` expected.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// Cells whose trilinear map has a negative Jacobian determinant at a corner.
    #[error("{count} inverted cell(s) (negative corner Jacobian), first is cell {first}")]
    InvertedCells {
        /// How many cells are inverted.
        count: usize,
        /// Index of the first.
        first: usize,
    },
}

/// `v` as a message shows it: the shortest text that reads back as `v`, in scientific
/// notation (`1e-300`, `2.5e20`) when plain digits would be long (below 10⁻⁴ or from 10¹⁶).
///
/// Rust's `{}` writes every digit of an `f64` (`1e-300` is 302 characters); every message
/// that echoes a number a caller gave, or one derived from it, goes through this instead.
///
/// ```
/// use cylvol::error::show_number;
/// assert_eq!(show_number(1e-300), "1e-300");
/// assert_eq!(show_number(0.25), "0.25");
/// assert_eq!(show_number(f64::NAN), "NaN");
/// ```
pub fn show_number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e16).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A point or vector as a message shows it, `(x, y, z)`, each by [`show_number`].
pub fn show_vector(v: [f64; 3]) -> String {
    let [x, y, z] = v.map(show_number);
    format!("({x}, {y}, {z})")
}

fn list_types(types: &[(u8, &'static str, usize)]) -> String {
    types
        .iter()
        .map(|(code, name, count)| format!("{count} × {name} (VTK type {code})"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The value of `all` whose `name` is `s`, for `FromStr` of the enums named on the command
/// line; otherwise [`Error::Invalid`] naming `what` and listing the names
/// ("unknown structure 'x' (expected cart-grid, cyl-grid, cart-bvh or cyl-bvh)").
pub(crate) fn by_name<T: Copy>(
    all: &[T],
    name: impl Fn(T) -> &'static str,
    s: &str,
    what: &str,
) -> Result<T, Error> {
    if let Some(&v) = all.iter().find(|&&v| name(v) == s) {
        return Ok(v);
    }
    let names: Vec<&str> = all.iter().map(|&v| name(v)).collect();
    let expected = match names.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    };
    Err(Error::Invalid(format!(
        "unknown {what} '{s}' (expected {expected})"
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_shown_short_and_read_back() {
        for (v, text) in [
            (1e-300, "1e-300"),
            (-1e-300, "-1e-300"),
            (2.5e20, "2.5e20"),
            (1e16, "1e16"),
            (0.25, "0.25"),
            (-3.0, "-3"),
            (1234.5, "1234.5"),
            (0.0001, "0.0001"),
            (0.00001, "1e-5"),
            (0.0, "0"),
            (f64::INFINITY, "inf"),
            (f64::NAN, "NaN"),
            (f64::MIN_POSITIVE / 8.0, "2.781342323134e-309"),
        ] {
            assert_eq!(show_number(v), text, "{v:?}");
            if v.is_finite() {
                assert_eq!(show_number(v).parse::<f64>().unwrap(), v);
            }
        }
        for k in -320..=308 {
            let v = 1.7 * 10f64.powi(k);
            assert!(show_number(v).len() <= 24, "{v:e}: {}", show_number(v));
        }
        assert_eq!(show_vector([1e-300, -2.0, 0.5]), "(1e-300, -2, 0.5)");
    }

    #[test]
    fn by_name_finds_or_lists_the_names() {
        let all = [1u8, 2, 3];
        let name = |v: u8| ["", "one", "two", "three"][v as usize];
        assert_eq!(by_name(&all, name, "two", "number").unwrap(), 2);
        let err = by_name(&all, name, "four", "number").unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown number 'four' (expected one, two or three)"
        );
    }
}
