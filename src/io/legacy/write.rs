//! The legacy VTK writer: an `UNSTRUCTURED_GRID`, BINARY or ASCII, with the classic or the
//! VTK 5.1 `CELLS` layout.

use std::io::{self, Write};

use super::{CellLayout, Encoding, LegacyOptions};
use crate::mesh::{DataArray, Mesh};

/// Buffered output of keyword lines and value blocks.
struct Out<'w> {
    out: &'w mut dyn Write,
    buf: Vec<u8>,
    ascii: bool,
}

const FLUSH_AT: usize = 1 << 20;

impl Out<'_> {
    fn text(&mut self, s: &str) -> io::Result<()> {
        self.buf.extend_from_slice(s.as_bytes());
        self.maybe_flush()
    }

    fn maybe_flush(&mut self) -> io::Result<()> {
        if self.buf.len() >= FLUSH_AT {
            self.flush()?;
        }
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.write_all(&self.buf)?;
        self.buf.clear();
        Ok(())
    }

    /// `f64` values, `per_line` to a line in ASCII, then the newline ending the block.
    fn doubles(&mut self, values: impl Iterator<Item = f64>, per_line: usize) -> io::Result<()> {
        for (i, v) in values.enumerate() {
            if self.ascii {
                push_f64(&mut self.buf, v);
                self.buf
                    .push(if (i + 1) % per_line == 0 { b'\n' } else { b' ' });
            } else {
                self.buf.extend_from_slice(&v.to_be_bytes());
            }
            self.maybe_flush()?;
        }
        self.end_block()
    }

    /// Integers, as 4-byte (`wide = false`) or 8-byte big-endian values in binary.
    fn ints(
        &mut self,
        values: impl Iterator<Item = i64>,
        per_line: usize,
        wide: bool,
    ) -> io::Result<()> {
        for (i, v) in values.enumerate() {
            if self.ascii {
                let _ = write!(self.buf, "{v}");
                self.buf
                    .push(if (i + 1) % per_line == 0 { b'\n' } else { b' ' });
            } else if wide {
                self.buf.extend_from_slice(&v.to_be_bytes());
            } else {
                // Callers check that values fit 32 bits before choosing `wide = false`.
                self.buf.extend_from_slice(&(v as i32).to_be_bytes());
            }
            self.maybe_flush()?;
        }
        self.end_block()
    }

    fn end_block(&mut self) -> io::Result<()> {
        if self.buf.last() != Some(&b'\n') || !self.ascii {
            self.buf.push(b'\n');
        }
        self.maybe_flush()
    }
}

/// Shortest text that reads back as exactly `v` (C's `strtod` and Rust's parser alike).
fn push_f64(buf: &mut Vec<u8>, v: f64) {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) {
        let _ = write!(buf, "{v}");
    } else {
        let _ = write!(buf, "{v:e}");
    }
}

/// A name as one word: bytes other than printable ASCII (and `%`) become `%XX`, as VTK's
/// writer encodes them; an empty name gets `fallback`.
fn encode_name(name: &str, fallback: &str) -> String {
    if name.is_empty() {
        return fallback.to_string();
    }
    let mut out = String::with_capacity(name.len());
    for &b in name.as_bytes() {
        if b.is_ascii_graphic() && b != b'%' {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

pub(super) fn write(mesh: &Mesh, out: &mut dyn Write, options: &LegacyOptions) -> io::Result<()> {
    let ascii = options.encoding == Encoding::Ascii;
    let mut o = Out {
        out,
        buf: Vec::with_capacity(FLUSH_AT + 4096),
        ascii,
    };
    let kinds = mesh.kinds();
    let cells = mesh.cells();
    let n_cells = cells.len();
    let connectivity_len: usize = kinds.iter().map(|k| k.vertex_count()).sum();
    let classic_size = connectivity_len + n_cells;
    let fits_32 = mesh.point_count() <= i32::MAX as usize && classic_size <= i32::MAX as usize;
    let classic = options.cell_layout == CellLayout::Classic && fits_32;

    o.text(&format!(
        "# vtk DataFile Version {}\ncylvol mesh\n{}\nDATASET UNSTRUCTURED_GRID\n",
        if classic { "3.0" } else { "5.1" },
        if ascii { "ASCII" } else { "BINARY" }
    ))?;

    o.text(&format!("POINTS {} double\n", mesh.point_count()))?;
    o.doubles(mesh.points().iter().flat_map(|p| p.to_array()), 3)?;

    if classic {
        o.text(&format!("CELLS {n_cells} {classic_size}\n"))?;
        if ascii {
            // One cell to a line.
            for (c, k) in cells.iter().zip(kinds) {
                let _ = write!(o.buf, "{}", k.vertex_count());
                for &s in k.vtk_slots() {
                    let _ = write!(o.buf, " {}", c[s]);
                }
                o.buf.push(b'\n');
                o.maybe_flush()?;
            }
        } else {
            let list = cells.iter().zip(kinds).flat_map(|(c, k)| {
                std::iter::once(k.vertex_count() as i64)
                    .chain(k.vtk_slots().iter().map(move |&s| i64::from(c[s])))
            });
            o.ints(list, usize::MAX, false)?;
        }
    } else {
        o.text(&format!("CELLS {} {connectivity_len}\n", n_cells + 1))?;
        o.text("OFFSETS vtktypeint64\n")?;
        let offsets = std::iter::once(0).chain(mesh.vtk_cell_ends());
        o.ints(offsets.map(|end| end as i64), 9, true)?;
        o.text("CONNECTIVITY vtktypeint64\n")?;
        o.ints(mesh.vtk_connectivity().map(i64::from), 8, true)?;
    }

    o.text(&format!("CELL_TYPES {n_cells}\n"))?;
    o.ints(mesh.vtk_cell_types().map(i64::from), 1, false)?;

    for (keyword, count, arrays) in [
        ("CELL_DATA", n_cells, mesh.cell_data()),
        ("POINT_DATA", mesh.point_count(), mesh.point_data()),
    ] {
        if !arrays.is_empty() {
            o.text(&format!("{keyword} {count}\n"))?;
            write_arrays(&mut o, arrays, count)?;
        }
    }
    o.flush()
}

/// The arrays of one attribute section, in order (see the module documentation).
fn write_arrays(o: &mut Out, arrays: &[DataArray], tuples: usize) -> io::Result<()> {
    let (mut scalars_done, mut vectors_done) = (false, false);
    for (i, a) in arrays.iter().enumerate() {
        let name = encode_name(&a.name, &format!("array{i}"));
        let comps = a.components.max(1);
        if comps == 1 && !scalars_done {
            scalars_done = true;
            o.text(&format!("SCALARS {name} double 1\nLOOKUP_TABLE default\n"))?;
        } else if comps == 3 && !vectors_done {
            vectors_done = true;
            o.text(&format!("VECTORS {name} double\n"))?;
        } else {
            o.text(&format!(
                "FIELD FieldData 1\n{name} {comps} {tuples} double\n"
            ))?;
        }
        o.doubles(a.values.iter().copied(), comps)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_single_words() {
        assert_eq!(encode_name("p", "x"), "p");
        assert_eq!(encode_name("total pressure%", "x"), "total%20pressure%25");
        assert_eq!(encode_name("", "array3"), "array3");
    }

    #[test]
    fn ascii_numbers_read_back_exactly() {
        for v in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1e-300,
            3.5e20,
            -2.5e-7,
            123456.789,
            f64::MAX,
        ] {
            let mut buf = Vec::new();
            push_f64(&mut buf, v);
            let text = String::from_utf8(buf).unwrap();
            assert_eq!(text.parse::<f64>().unwrap(), v, "{text}");
        }
    }
}
