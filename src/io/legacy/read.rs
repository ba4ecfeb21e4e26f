//! The legacy VTK reader: header, then the sections of an `UNSTRUCTURED_GRID` or
//! `STRUCTURED_GRID` in whatever order they come, then the mesh.

use glam::DVec3;

use std::borrow::Cow;

use super::cursor::{show, Cursor, Shortfall, Token};
use super::values::{parse_f64, parse_i64, ArrayType, ValueType};
use crate::error::{Error, ReadError};
use crate::io::elements::{to_f64, to_tuples, Integers, ScalarType};
use crate::io::empty::{self, drop_tuples};
use crate::io::ghost::{drop_ghost_cells, Blanking};
use crate::io::structured::hexahedra;
use crate::mesh::{cells_from_ids, Association, CellKind, DataArray, Mesh, MeshParts, OffsetStyle};

/// The dataset types this reader turns into meshes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dataset {
    Unstructured,
    Structured,
}

/// What a value block is, for messages: `"POINTS"` section, counted in `"points"`.
#[derive(Clone, Copy)]
struct What<'s> {
    section: &'s str,
    unit: &'s str,
}

/// A section's values and the offset of its keyword.
struct At<T> {
    value: T,
    offset: usize,
}

impl<T> At<T> {
    fn new(value: T, offset: usize) -> At<T> {
        At { value, offset }
    }
}

/// Integers of a cell array as read, as big-endian elements of an integer type: a binary
/// file's block as it is, read a value at a time where the cells are converted (no copy of
/// the file's largest array), or an ASCII file's values stored the same way.
struct Ids<'a> {
    bytes: Cow<'a, [u8]>,
    ty: ScalarType,
}

impl Ids<'_> {
    /// Parsed values, stored as big-endian `i64`s.
    fn from_values(values: &[i64]) -> Ids<'static> {
        Ids {
            bytes: Cow::Owned(values.iter().flat_map(|v| v.to_be_bytes()).collect()),
            ty: ScalarType::I64,
        }
    }

    /// The values, to be read one at a time.
    fn view(&self) -> Integers<'_> {
        Integers::new(&self.bytes, self.ty, true).unwrap_or(Integers::EMPTY)
    }
}

/// The `CELLS` section: where each cell's span of `ids` starts (`n + 1` entries, the last
/// where the list ends) and how many values lead each span before its ids (1 in the classic
/// layout, where they are each cell's vertex count; 0 in VTK 5.1's `CONNECTIVITY`).
struct CellList<'a> {
    starts: Vec<i64>,
    skip: usize,
    ids: Ids<'a>,
}

/// Everything read from the file, before it becomes a mesh.
struct Parsed<'a> {
    dataset: Dataset,
    points: Option<At<Vec<DVec3>>>,
    dims: Option<At<[usize; 3]>>,
    cells: Option<At<CellList<'a>>>,
    types: Option<At<Vec<u8>>>,
    point_count: Option<At<usize>>,
    cell_count: Option<At<usize>>,
    point_data: Vec<DataArray>,
    cell_data: Vec<DataArray>,
}

struct Parser<'a> {
    c: Cursor<'a>,
    binary: bool,
}

type Result<T> = std::result::Result<T, ReadError>;

/// Reads a legacy VTK file's bytes into a mesh (see [`super::read`]), giving `log` what was
/// done beyond reading (cells dropped, and why).
pub(super) fn read(bytes: &[u8], log: &mut dyn FnMut(String)) -> std::result::Result<Mesh, Error> {
    let mut parser = Parser {
        c: Cursor::new(bytes),
        binary: false,
    };
    let dataset = parser.header()?;
    let parsed = parser.parse(dataset)?;
    parser.build_mesh(parsed, log)
}

/// Reads a BINARY legacy VTK file of `len` bytes from disk as it is parsed: each binary block
/// with positioned reads of exactly its bytes, decoded and dropped before the next, and the
/// text between them `chunk` bytes at a time; so the file is never held whole. Gives what
/// [`read`] gives for the file's bytes (mesh or error), and `None` for an ASCII file, which
/// is better read whole (see [`super::read_file`]).
#[cfg(unix)]
pub(super) fn read_file(
    file: &std::fs::File,
    len: usize,
    chunk: usize,
    log: &mut dyn FnMut(String),
) -> Option<std::result::Result<Mesh, Error>> {
    let mut parser = Parser {
        c: Cursor::over_file(file, len, chunk),
        binary: false,
    };
    let dataset = match parser.header() {
        Ok(dataset) if parser.binary => dataset,
        Ok(_) => return None,
        Err(e) => return Some(Err(e.into())),
    };
    Some(
        parser
            .parse(dataset)
            .map_err(Error::from)
            .and_then(|parsed| parser.build_mesh(parsed, log)),
    )
}

/// Decodes VTK's `%XX` escapes in names (the writer escapes spaces and other special bytes).
fn decode_name(word: &[u8]) -> String {
    let mut out = Vec::with_capacity(word.len());
    let mut i = 0;
    while i < word.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if word[i] == b'%' && i + 2 < word.len() {
            if let (Some(h), Some(l)) = (hex(word[i + 1]), hex(word[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(word[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

impl<'a> Parser<'a> {
    fn err(&self, offset: usize, message: impl Into<String>) -> ReadError {
        self.c.error(offset, message)
    }

    /// The next word, or an error saying what was expected where the file ends.
    fn expect(&mut self, what: &str) -> Result<Token<'a>> {
        self.c
            .token()
            .ok_or_else(|| self.err(self.c.len(), format!("file ends where {what} was expected")))
    }

    /// The next word, which must be `keyword` (any case).
    fn keyword(&mut self, keyword: &str, context: &str) -> Result<Token<'a>> {
        let t = self.expect(&format!("{keyword} ({context})"))?;
        if t.is(keyword) {
            Ok(t)
        } else {
            Err(self.err(
                t.offset,
                format!("expected {keyword} ({context}), found '{}'", t.show()),
            ))
        }
    }

    /// A non-negative integer count.
    fn count(&mut self, what: &str) -> Result<usize> {
        let t = self.expect(what)?;
        parse_i64(&t.text)
            .and_then(|v| usize::try_from(v).ok())
            .ok_or_else(|| {
                self.err(
                    t.offset,
                    format!(
                        "expected {what} (a non-negative integer), found '{}'",
                        t.show()
                    ),
                )
            })
    }

    fn value_type(&mut self, what: &str) -> Result<ValueType> {
        let t = self.expect(&format!("the data type of {what}"))?;
        ValueType::parse(&t.text).map_err(|m| self.err(t.offset, format!("{what}: {m}")))
    }

    /// The data type of a `FIELD` array or `PEDIGREE_IDS`, which may be strings or variants.
    fn array_type(&mut self, what: &str) -> Result<ArrayType> {
        let t = self.expect(&format!("the data type of {what}"))?;
        ArrayType::parse(&t.text).map_err(|m| self.err(t.offset, format!("{what}: {m}")))
    }

    /// The data type of an attribute that holds numbers (bits among them).
    fn numeric_type(&mut self, what: &str) -> Result<ArrayType> {
        let t = self.expect(&format!("the data type of {what}"))?;
        ArrayType::parse_numeric(&t.text).map_err(|m| self.err(t.offset, format!("{what}: {m}")))
    }

    fn truncated(&self, what: What, done: usize, total: usize) -> ReadError {
        self.err(
            self.c.len(),
            format!(
                "file ends inside {} after {done} of {total} {}",
                what.section, what.unit
            ),
        )
    }

    fn too_large(&self, offset: usize, what: What) -> ReadError {
        self.err(offset, format!("{} is too large to exist", what.section))
    }

    /// The raw bytes of `tuples × comps` binary values.
    fn binary_block(
        &mut self,
        ty: ValueType,
        tuples: usize,
        comps: usize,
        what: What,
    ) -> Result<Cow<'a, [u8]>> {
        let n = tuples
            .checked_mul(comps)
            .and_then(|n| n.checked_mul(ty.size()))
            .ok_or_else(|| self.too_large(self.c.pos(), what))?;
        self.bytes_of(n, tuples, what, |available| available / (comps * ty.size()))
    }

    /// The `n` bytes of a binary block of `tuples` tuples (none if `n` is 0); where the file
    /// ends first, an error saying how many tuples the `available` bytes held (`held`).
    fn bytes_of(
        &mut self,
        n: usize,
        tuples: usize,
        what: What,
        held: impl Fn(usize) -> usize,
    ) -> Result<Cow<'a, [u8]>> {
        if n == 0 {
            return Ok(Cow::Borrowed(&[]));
        }
        let start = self.c.pos();
        self.c.binary(n).map_err(|shortfall| match shortfall {
            Shortfall::Truncated(available) => self.truncated(what, held(available), tuples),
            Shortfall::Io(e) => self.err(
                start,
                format!("could not read {n} bytes of {}: {e}", what.section),
            ),
        })
    }

    /// Reads `tuples × comps` bits as 0 and 1, as `vtkDataReader` reads a `bit` array: in a
    /// binary file packed eight a byte after the rest of the keyword line, the first value in
    /// the high bit; in an ASCII file one integer a value, any but 0 meaning 1.
    fn bits(&mut self, tuples: usize, comps: usize, what: What) -> Result<Vec<f64>> {
        let n = tuples
            .checked_mul(comps)
            .ok_or_else(|| self.too_large(self.c.pos(), what))?;
        if self.binary {
            let block = self.bytes_of(n.div_ceil(8), tuples, what, |available| {
                available * 8 / comps.max(1)
            })?;
            return Ok((0..n)
                .map(|i| f64::from((block[i / 8] >> (7 - i % 8)) & 1))
                .collect());
        }
        let mut out = Vec::with_capacity(n.min(self.c.remaining() / 2 + 1));
        for i in 0..n {
            let t = self
                .c
                .token()
                .ok_or_else(|| self.truncated(what, i / comps, tuples))?;
            let v = parse_i64(&t.text).ok_or_else(|| {
                self.err(
                    t.offset,
                    format!(
                        "'{}' in {} is not an integer (bits are 0 or 1)",
                        t.show(),
                        what.section
                    ),
                )
            })?;
            out.push(if v == 0 { 0.0 } else { 1.0 });
        }
        Ok(out)
    }

    /// An array of `tuples` tuples of `comps` values of type `ty` (named `section` in
    /// errors), with any metadata after it skipped: numbers, bits as 0 and 1 (VTK's
    /// `vtkBitArray` is a numeric array), and `None` for strings and variants, which are read
    /// past, as the VTU reader skips string arrays (no mesh array can hold them).
    fn data_array(
        &mut self,
        name: String,
        ty: ArrayType,
        tuples: usize,
        comps: usize,
        section: &str,
    ) -> Result<Option<DataArray>> {
        let what = What {
            section,
            unit: "tuples",
        };
        let values = match ty {
            ArrayType::Number(ty) => Some(self.values_f64(ty, tuples, comps, what)?),
            ArrayType::Bit => Some(self.bits(tuples, comps, what)?),
            ArrayType::String => {
                self.skip_strings(tuples, comps, what)?;
                None
            }
            ArrayType::Variant => {
                self.skip_variants(tuples, comps, what)?;
                None
            }
        };
        self.skip_metadata();
        Ok(values.map(|values| DataArray {
            name,
            components: comps,
            values,
        }))
    }

    /// Reads past `tuples × comps` strings as `vtkDataReader` reads them. In a binary file:
    /// after the rest of the keyword line, each value's length in a big-endian header whose
    /// first byte's two high bits say its size — `11`: 1 byte, `10`: 2, `01`: 4 (the rest of
    /// the header's bits the length), `00`: 8 (all 64 the length) — then that many bytes.
    /// In an ASCII file: after the rest of the keyword line, one line a value (an empty line
    /// an empty string).
    fn skip_strings(&mut self, tuples: usize, comps: usize, what: What) -> Result<()> {
        let n = tuples
            .checked_mul(comps)
            .ok_or_else(|| self.too_large(self.c.pos(), what))?;
        if n == 0 {
            return Ok(());
        }
        if !self.binary {
            let _ = self.c.line();
            for i in 0..n {
                if self.c.line().is_none() {
                    return Err(self.truncated(what, i / comps, tuples));
                }
            }
            return Ok(());
        }
        self.c.start_binary();
        for i in 0..n {
            let truncated = |this: &Self| this.truncated(what, i / comps, tuples);
            let first = self.c.byte().ok_or_else(|| truncated(self))?;
            let (mut len, more) = match first >> 6 {
                3 => (u64::from(first & 0x3f), 0),
                2 => (u64::from(first & 0x3f), 1),
                1 => (u64::from(first & 0x3f), 3),
                _ => (u64::from(first), 7),
            };
            for _ in 0..more {
                let b = self.c.byte().ok_or_else(|| truncated(self))?;
                len = len << 8 | u64::from(b);
            }
            if !self.c.skip(len) {
                return Err(truncated(self));
            }
        }
        Ok(())
    }

    /// Reads past `tuples × comps` variants: each a VTK type code (an integer) and a word, as
    /// text in both encodings.
    fn skip_variants(&mut self, tuples: usize, comps: usize, what: What) -> Result<()> {
        let n = tuples
            .checked_mul(comps)
            .ok_or_else(|| self.too_large(self.c.pos(), what))?;
        for i in 0..n {
            let truncated = |this: &Self| this.truncated(what, i / comps, tuples);
            let code = self.c.token().ok_or_else(|| truncated(self))?;
            if parse_i64(&code.text).is_none() {
                return Err(self.err(
                    code.offset,
                    format!(
                        "'{}' in {} is not a VTK type code",
                        code.show(),
                        what.section
                    ),
                ));
            }
            self.c.token().ok_or_else(|| truncated(self))?;
        }
        Ok(())
    }

    /// Reads `tuples × comps` values of type `ty` as `f64`.
    fn values_f64(
        &mut self,
        ty: ValueType,
        tuples: usize,
        comps: usize,
        what: What,
    ) -> Result<Vec<f64>> {
        if self.binary {
            let block = self.binary_block(ty, tuples, comps, what)?;
            return Ok(to_f64(&block, ty.element(), true));
        }
        let n = tuples
            .checked_mul(comps)
            .ok_or_else(|| self.too_large(self.c.pos(), what))?;
        let mut out = Vec::with_capacity(n.min(self.c.remaining() / 2 + 1));
        for i in 0..n {
            let t = self
                .c
                .token()
                .ok_or_else(|| self.truncated(what, i / comps, tuples))?;
            // VTK reads `float` text into a float: round the same way, so values agree.
            let parsed = if ty == ValueType::Float {
                std::str::from_utf8(&t.text)
                    .ok()
                    .and_then(|s| s.parse::<f32>().ok())
                    .map(f64::from)
            } else {
                parse_f64(&t.text)
            };
            let v = parsed.ok_or_else(|| {
                self.err(
                    t.offset,
                    format!("'{}' in {} is not a number", t.show(), what.section),
                )
            })?;
            out.push(v);
        }
        Ok(out)
    }

    /// Reads `n` integer values of type `ty` (cell arrays): a binary block as it is, to be
    /// read a value at a time, or an ASCII file's values.
    fn ids(&mut self, ty: ValueType, n: usize, what: What, ty_at: usize) -> Result<Ids<'a>> {
        if !ty.is_integer() {
            return Err(self.err(ty_at, format!("{} must hold integers", what.section)));
        }
        if self.binary {
            let block = self.binary_block(ty, n, 1, what)?;
            return Ok(Ids {
                bytes: block,
                ty: ty.element(),
            });
        }
        Ok(Ids::from_values(&self.ascii_i64(n, what)?))
    }

    /// Reads `n` ASCII integers.
    fn ascii_i64(&mut self, n: usize, what: What) -> Result<Vec<i64>> {
        let mut out = Vec::with_capacity(n.min(self.c.remaining() / 2 + 1));
        for i in 0..n {
            let t = self.c.token().ok_or_else(|| self.truncated(what, i, n))?;
            let v = parse_i64(&t.text).ok_or_else(|| {
                self.err(
                    t.offset,
                    format!("'{}' in {} is not an integer", t.show(), what.section),
                )
            })?;
            out.push(v);
        }
        Ok(out)
    }

    /// Skips a VTK 9 `METADATA` block (and its `INFORMATION`) if one comes next: lines up to
    /// the first blank one, as VTK reads it.
    fn skip_metadata(&mut self) {
        while self
            .c
            .peek_token()
            .is_some_and(|t| t.is("METADATA") || t.is("INFORMATION"))
        {
            let _ = self.c.token();
            self.skip_block();
        }
    }

    /// Skips the rest of the current line, then lines up to and including a blank one.
    fn skip_block(&mut self) {
        let _ = self.c.line();
        while let Some(line) = self.c.line() {
            if line.iter().all(u8::is_ascii_whitespace) {
                break;
            }
        }
    }

    /// The sections after the header.
    fn parse(&mut self, dataset: Dataset) -> Result<Parsed<'a>> {
        let mut p = Parsed {
            dataset,
            points: None,
            dims: None,
            cells: None,
            types: None,
            point_count: None,
            cell_count: None,
            point_data: Vec::new(),
            cell_data: Vec::new(),
        };
        // The attribute section (POINT_DATA or CELL_DATA) arrays currently belong to.
        let mut section: Option<(Association, usize)> = None;
        while let Some(t) = self.c.token() {
            let at = t.offset;
            let duplicate = |this: &Self, present: bool| {
                if present {
                    Err(this.err(at, format!("a second {} section", t.show())))
                } else {
                    Ok(())
                }
            };
            if t.is("POINTS") {
                duplicate(self, p.points.is_some())?;
                p.points = Some(At::new(self.points()?, at));
            } else if t.is("DIMENSIONS") && dataset == Dataset::Structured {
                duplicate(self, p.dims.is_some())?;
                let dims = [
                    self.count("the i dimension")?,
                    self.count("the j dimension")?,
                    self.count("the k dimension")?,
                ];
                p.dims = Some(At::new(dims, at));
            } else if t.is("CELLS") && dataset == Dataset::Unstructured {
                duplicate(self, p.cells.is_some())?;
                p.cells = Some(At::new(self.cells()?, at));
            } else if t.is("CELL_TYPES") && dataset == Dataset::Unstructured {
                duplicate(self, p.types.is_some())?;
                p.types = Some(At::new(self.cell_types()?, at));
            } else if t.is("POINT_DATA") || t.is("CELL_DATA") {
                let association = if t.is("POINT_DATA") {
                    Association::Point
                } else {
                    Association::Cell
                };
                let slot = match association {
                    Association::Point => &p.point_count,
                    Association::Cell => &p.cell_count,
                };
                duplicate(self, slot.is_some())?;
                let n = self.count(&format!("the number of tuples of {}", t.show()))?;
                let count = Some(At::new(n, at));
                match association {
                    Association::Point => p.point_count = count,
                    Association::Cell => p.cell_count = count,
                }
                section = Some((association, n));
            } else if t.is("FIELD") {
                let arrays = self.field(section)?;
                match section {
                    Some((Association::Point, _)) => p.point_data.extend(arrays),
                    Some((Association::Cell, _)) => p.cell_data.extend(arrays),
                    None => {} // dataset-level field data (TimeValue …): not per point or cell
                }
            } else if t.is("METADATA") || t.is("INFORMATION") {
                self.skip_block();
            } else if let Some((association, n)) = section {
                if let Some(array) = self.attribute(t, association, n)? {
                    match association {
                        Association::Point => p.point_data.push(array),
                        Association::Cell => p.cell_data.push(array),
                    }
                }
            } else {
                return Err(self.err(
                    at,
                    format!(
                        "unexpected keyword '{}' in a {} dataset",
                        t.show(),
                        match dataset {
                            Dataset::Unstructured => "UNSTRUCTURED_GRID",
                            Dataset::Structured => "STRUCTURED_GRID",
                        }
                    ),
                ));
            }
        }
        Ok(p)
    }

    /// The four header lines; returns the dataset type.
    fn header(&mut self) -> Result<Dataset> {
        const MAGIC: &[u8] = b"# vtk DataFile Version";
        let first = self.c.line().unwrap_or_default();
        if first.len() < MAGIC.len() || !first[..MAGIC.len()].eq_ignore_ascii_case(MAGIC) {
            return Err(self.err(
                0,
                format!(
                    "not a legacy VTK file: the first line should start with '# vtk DataFile Version', found '{}'",
                    show(&first)
                ),
            ));
        }
        if self.c.line().is_none() {
            return Err(self.err(self.c.len(), "file ends inside the header (no title line)"));
        }
        let t = self.expect("ASCII or BINARY")?;
        self.binary = if t.is("ASCII") {
            false
        } else if t.is("BINARY") {
            true
        } else {
            return Err(self.err(
                t.offset,
                format!("expected ASCII or BINARY, found '{}'", t.show()),
            ));
        };
        self.keyword("DATASET", "after the file type")?;
        let t = self.expect("the dataset type")?;
        if t.is("UNSTRUCTURED_GRID") {
            Ok(Dataset::Unstructured)
        } else if t.is("STRUCTURED_GRID") {
            Ok(Dataset::Structured)
        } else {
            Err(self.err(
                t.offset,
                format!(
                    "dataset type {} is not supported (only UNSTRUCTURED_GRID and STRUCTURED_GRID)",
                    t.show()
                ),
            ))
        }
    }

    fn points(&mut self) -> Result<Vec<DVec3>> {
        let n = self.count("the number of points")?;
        let ty = self.value_type("POINTS")?;
        let what = What {
            section: "POINTS",
            unit: "points",
        };
        let points = if self.binary {
            let block = self.binary_block(ty, n, 3, what)?;
            to_tuples(&block, ty.element(), true, DVec3::from_array)
        } else {
            let v = self.values_f64(ty, n, 3, what)?;
            v.chunks_exact(3).map(DVec3::from_slice).collect()
        };
        self.skip_metadata();
        Ok(points)
    }

    /// `CELLS`, in the classic layout (a count before each cell's ids) or VTK 5.1's
    /// (`OFFSETS` and `CONNECTIVITY` arrays).
    fn cells(&mut self) -> Result<CellList<'a>> {
        let a = self.count("the number of cells")?;
        let b = self.count("the size of the cell list")?;
        if self.c.peek_token().is_some_and(|t| t.is("OFFSETS")) {
            let _ = self.c.token();
            let ty_at = self.c.pos();
            let ty = self.value_type("OFFSETS")?;
            let what = What {
                section: "CELLS OFFSETS",
                unit: "offsets",
            };
            let offsets = self.ids(ty, a, what, ty_at)?;
            self.skip_metadata();
            self.keyword("CONNECTIVITY", "after the CELLS OFFSETS")?;
            let ty_at = self.c.pos();
            let ty = self.value_type("CONNECTIVITY")?;
            let what = What {
                section: "CELLS CONNECTIVITY",
                unit: "ids",
            };
            let ids = self.ids(ty, b, what, ty_at)?;
            self.skip_metadata();
            let starts = if a == 0 {
                vec![0]
            } else {
                offsets.view().to_vec()
            };
            return Ok(CellList {
                starts,
                skip: 0,
                ids,
            });
        }
        if a == 0 {
            return Ok(CellList {
                starts: vec![0],
                skip: 0,
                ids: Ids::from_values(&[]),
            });
        }
        // Classic layout: 4-byte ints in binary files.
        let at = self.c.pos();
        let what = What {
            section: "CELLS",
            unit: "values",
        };
        let ids = self.ids(ValueType::Int, b, what, at)?;
        let view = ids.view();
        let starts = counted_starts(a, view.len(), |i| view.get(i)).map_err(|m| self.err(at, m))?;
        Ok(CellList {
            starts,
            skip: 1,
            ids,
        })
    }

    fn cell_types(&mut self) -> Result<Vec<u8>> {
        let n = self.count("the number of cell types")?;
        let at = self.c.pos();
        let what = What {
            section: "CELL_TYPES",
            unit: "cell types",
        };
        let codes = self.ids(ValueType::Int, n, what, at)?;
        let codes = codes.view();
        self.skip_metadata();
        (0..codes.len())
            .map(|i| {
                let code = codes.get(i);
                u8::try_from(code).map_err(|_| {
                    self.err(at, format!("cell {i} has an invalid cell type code {code}"))
                })
            })
            .collect()
    }

    /// A `FIELD name n` block: its arrays, each checked against the attribute section's tuple
    /// count when there is one.
    fn field(&mut self, section: Option<(Association, usize)>) -> Result<Vec<DataArray>> {
        let _name = self.expect("the FIELD name")?;
        let n = self.count("the number of FIELD arrays")?;
        let mut arrays = Vec::new();
        for _ in 0..n {
            let name = self.expect("a FIELD array name")?;
            if *name.text == *b"NULL_ARRAY" {
                continue;
            }
            let array_name = decode_name(&name.text);
            let comps = self.count(&format!("the components of FIELD array '{array_name}'"))?;
            let tuples = self.count(&format!("the tuples of FIELD array '{array_name}'"))?;
            let ty = self.array_type(&format!("FIELD array '{array_name}'"))?;
            let section_name = format!("FIELD array '{array_name}'");
            let Some(array) = self.data_array(array_name, ty, tuples, comps, &section_name)? else {
                continue; // strings and variants: not per point or cell values
            };
            if let Some((association, expected)) = section {
                if tuples != expected {
                    return Err(self.err(
                        name.offset,
                        format!(
                            "{association} FIELD array '{}' has {tuples} tuples, but the section has {expected}",
                            array.name
                        ),
                    ));
                }
                if comps > 0 {
                    arrays.push(array);
                }
            }
        }
        Ok(arrays)
    }

    /// One attribute of a `POINT_DATA` / `CELL_DATA` section with `n` tuples: the array to keep
    /// (scalars, vectors, normals), or `None` for what is read and dropped.
    fn attribute(
        &mut self,
        t: Token<'a>,
        association: Association,
        n: usize,
    ) -> Result<Option<DataArray>> {
        let label = |kind: &str, name: &str| format!("{association} {kind} '{name}'");
        if t.is("SCALARS") {
            let name = decode_name(&self.expect("the SCALARS name")?.text);
            let ty = self.numeric_type(&label("SCALARS", &name))?;
            let mut comps = 1;
            let next = self.expect("LOOKUP_TABLE after SCALARS")?;
            let next = if next.is("LOOKUP_TABLE") {
                next
            } else {
                comps = parse_i64(&next.text)
                    .and_then(|v| usize::try_from(v).ok())
                    .filter(|&v| v >= 1)
                    .ok_or_else(|| {
                        self.err(
                            next.offset,
                            format!(
                                "SCALARS '{name}': expected a number of components or LOOKUP_TABLE, found '{}'",
                                next.show()
                            ),
                        )
                    })?;
                self.expect("LOOKUP_TABLE after SCALARS")?
            };
            if !next.is("LOOKUP_TABLE") {
                return Err(self.err(
                    next.offset,
                    format!(
                        "SCALARS '{name}' must be followed by LOOKUP_TABLE, found '{}'",
                        next.show()
                    ),
                ));
            }
            let _table = self.expect("the LOOKUP_TABLE name")?;
            let section = label("SCALARS", &name);
            return self.data_array(name, ty, n, comps, &section);
        }
        let (keep, fixed_comps) = if t.is("VECTORS") || t.is("NORMALS") {
            (true, Some(3))
        } else if t.is("TENSORS") {
            (false, Some(9))
        } else if t.is("TENSORS6") {
            (false, Some(6))
        } else if t.is("GLOBAL_IDS") || t.is("PEDIGREE_IDS") || t.is("EDGE_FLAGS") {
            (false, Some(1))
        } else if t.is("TEXTURE_COORDINATES") {
            (false, None)
        } else if t.is("COLOR_SCALARS") {
            let name = decode_name(&self.expect("the COLOR_SCALARS name")?.text);
            let comps = self.count(&format!("the components of COLOR_SCALARS '{name}'"))?;
            let ty = if self.binary {
                ValueType::UnsignedChar
            } else {
                ValueType::Float
            };
            let section = label("COLOR_SCALARS", &name);
            self.values_f64(
                ty,
                n,
                comps,
                What {
                    section: &section,
                    unit: "tuples",
                },
            )?;
            self.skip_metadata();
            return Ok(None);
        } else if t.is("LOOKUP_TABLE") {
            let name = decode_name(&self.expect("the LOOKUP_TABLE name")?.text);
            let size = self.count(&format!("the size of LOOKUP_TABLE '{name}'"))?;
            let ty = if self.binary {
                ValueType::UnsignedChar
            } else {
                ValueType::Float
            };
            let section = format!("LOOKUP_TABLE '{name}'");
            self.values_f64(
                ty,
                size,
                4,
                What {
                    section: &section,
                    unit: "colours",
                },
            )?;
            return Ok(None);
        } else {
            return Err(self.err(
                t.offset,
                format!("unknown keyword '{}' in {association} data", t.show()),
            ));
        };
        let kind = t.show();
        let name = decode_name(&self.expect(&format!("the {kind} name"))?.text);
        let comps = match fixed_comps {
            Some(c) => c,
            None => {
                let c = self.count(&format!("the dimension of {kind} '{name}'"))?;
                if !(1..=3).contains(&c) {
                    return Err(self.err(
                        self.c.pos(),
                        format!("{kind} '{name}' has dimension {c}; expected 1 to 3"),
                    ));
                }
                c
            }
        };
        // Pedigree ids, which are dropped, may be strings, as VTK writes a string array set as
        // them; every other attribute holds numbers.
        let ty = if t.is("PEDIGREE_IDS") {
            self.array_type(&label(&kind, &name))?
        } else {
            self.numeric_type(&label(&kind, &name))?
        };
        let section = label(&kind, &name);
        let array = self.data_array(name, ty, n, comps, &section)?;
        Ok(array.filter(|_| keep))
    }

    /// Checks the sections against each other and builds the mesh, giving `log` what was
    /// dropped: empty cells (with their cell data), ghost and blanked cells.
    fn build_mesh(
        &self,
        p: Parsed<'a>,
        log: &mut dyn FnMut(String),
    ) -> std::result::Result<Mesh, Error> {
        let end = self.c.len();
        let points = p
            .points
            .ok_or_else(|| self.err(end, "the file has no POINTS section"))?;
        let n_points = points.value.len();
        let dataset = p.dataset;
        let (cells, kinds, empty) = match p.dataset {
            Dataset::Unstructured => match p.cells {
                None => (Vec::new(), Vec::new(), Vec::new()),
                Some(cells) => {
                    let CellList { starts, skip, ids } = &cells.value;
                    let ids = ids.view();
                    let n_cells = starts.len().saturating_sub(1);
                    let types = p.types.ok_or_else(|| {
                        self.err(end, "the file has CELLS but no CELL_TYPES section")
                    })?;
                    if types.value.len() != n_cells {
                        return Err(self
                            .err(
                                types.offset,
                                format!(
                                    "CELL_TYPES has {} entries, but CELLS (at byte {}) has {n_cells} cells",
                                    types.value.len(),
                                    cells.offset
                                ),
                            )
                            .into());
                    }
                    let converted = cells_from_ids(
                        ids.len(),
                        |k| ids.get(k),
                        starts,
                        OffsetStyle::Starts,
                        *skip,
                        &types.value,
                        n_points,
                    )?;
                    (converted.cells, converted.kinds, converted.empty)
                }
            },
            Dataset::Structured => {
                let dims = p
                    .dims
                    .ok_or_else(|| self.err(end, "the STRUCTURED_GRID has no DIMENSIONS"))?;
                let [ni, nj, nk] = dims.value;
                let expected = ni.checked_mul(nj).and_then(|v| v.checked_mul(nk));
                if expected != Some(n_points) {
                    return Err(self
                        .err(
                            points.offset,
                            format!(
                                "DIMENSIONS {ni} {nj} {nk} (at byte {}) need {} points, but POINTS has {n_points}",
                                dims.offset,
                                expected.map_or("too many".to_string(), |e| e.to_string())
                            ),
                        )
                        .into());
                }
                let cells = hexahedra(dims.value, &points.value);
                let kinds = vec![CellKind::Hexahedron; cells.len()];
                (cells, kinds, Vec::new())
            }
        };
        // The file's cells, empty ones included: the cell data's tuples.
        let file_cells = cells.len() + empty.len();
        for (declared, actual, keyword, what) in [
            (&p.point_count, n_points, "POINT_DATA", "points"),
            (&p.cell_count, file_cells, "CELL_DATA", "cells"),
        ] {
            if let Some(d) = declared {
                if d.value != actual {
                    return Err(self
                        .err(
                            d.offset,
                            format!(
                                "{keyword} has {} tuples, but the dataset has {actual} {what}",
                                d.value
                            ),
                        )
                        .into());
                }
            }
        }
        let mut parts = MeshParts {
            points: points.value,
            cells,
            kinds,
            point_data: p.point_data,
            cell_data: p.cell_data,
        };
        drop_tuples(&mut parts.cell_data, &empty, file_cells);
        let blanking = match dataset {
            Dataset::Unstructured => Blanking::Cells,
            Dataset::Structured => Blanking::CellsAndPoints,
        };
        let dropped = drop_ghost_cells(&mut parts, blanking);
        empty::note(empty.len()).into_iter().for_each(&mut *log);
        dropped.notes().into_iter().for_each(&mut *log);
        let mesh = Mesh::from_parts(parts)?;
        Ok(mesh)
    }
}

/// Where each of `cells` cells' records starts in a classic cell list of `len` values
/// (`value(i)` is the i-th), each record a vertex count and that many ids: `cells + 1`
/// entries, the last `len`. Every count must fit in what remains, and the records must use
/// the whole list.
fn counted_starts(
    cells: usize,
    len: usize,
    value: impl Fn(usize) -> i64,
) -> std::result::Result<Vec<i64>, String> {
    let mut starts = Vec::with_capacity(cells.min(len) + 1);
    let mut read = 0usize;
    for cell in 0..cells {
        if read >= len {
            return Err(format!(
                "CELLS lists {cell} cells in {len} values, but claims {cells} cells"
            ));
        }
        starts.push(read as i64);
        let count = value(read);
        let remaining = len - read - 1;
        let count = usize::try_from(count)
            .ok()
            .filter(|&k| k <= remaining)
            .ok_or_else(|| {
                format!(
                    "CELLS: cell {cell} claims {count} points, but only {remaining} values remain"
                )
            })?;
        read += 1 + count;
    }
    if read != len {
        return Err(format!(
            "CELLS claims {len} values, but its {cells} cells use {read}"
        ));
    }
    starts.push(len as i64);
    Ok(starts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_percent_decoded() {
        assert_eq!(decode_name(b"my%20array"), "my array");
        assert_eq!(decode_name(b"100%"), "100%");
        assert_eq!(decode_name(b"%2"), "%2");
        assert_eq!(decode_name(b"%zz"), "%zz");
    }

    /// The binary files our writer makes in both cell layouts (a generated pump with its
    /// scalar, a vector and a cell array; a hand-written structured grid), read from disk as
    /// they are parsed, text scanned 1, 7, 64 and 65,536 bytes at a time: each gives what
    /// reading its bytes gives — the same mesh, or the same error (message, offset and line)
    /// when cut short at 40 places or with bytes overwritten at 40 others. ASCII files are
    /// left to the whole-file reader (`None`).
    #[cfg(unix)]
    #[test]
    fn reading_from_the_file_equals_reading_its_bytes() {
        use crate::io::legacy::{write_with, CellLayout, Encoding, LegacyOptions};
        use std::os::unix::fs::FileExt;

        let mut parts = crate::datasets::generate(crate::datasets::Dataset::PumpRotor, 1000)
            .unwrap()
            .into_parts();
        let n_points = parts.points.len();
        let n_cells = parts.cells.len();
        parts.point_data.push(DataArray {
            name: "velocity".into(),
            components: 3,
            values: (0..3 * n_points).map(|i| i as f64 * 0.5).collect(),
        });
        parts.cell_data.push(DataArray {
            name: "zone id".into(),
            components: 1,
            values: (0..n_cells).map(|i| (i % 5) as f64).collect(),
        });
        let mesh = Mesh::from_parts(parts).unwrap();
        let mut files = Vec::new();
        for cell_layout in [CellLayout::Classic, CellLayout::Vtk51] {
            let options = LegacyOptions {
                encoding: Encoding::Binary,
                cell_layout,
            };
            let mut bytes = Vec::new();
            write_with(&mesh, &mut bytes, &options).unwrap();
            files.push(bytes);
        }
        let mut structured = b"# vtk DataFile Version 3.0\nbox\nBINARY\nDATASET STRUCTURED_GRID\n\
            DIMENSIONS 2 2 2\nPOINTS 8 float\n"
            .to_vec();
        for k in 0..8u8 {
            for v in [k & 1, (k >> 1) & 1, k >> 2] {
                structured.extend(f32::from(v).to_be_bytes());
            }
        }
        structured.extend(b"\nPOINT_DATA 8\nSCALARS t int 1\nLOOKUP_TABLE default\n");
        structured.extend((0..8i32).flat_map(i32::to_be_bytes));
        structured.extend(b"\n");
        files.push(structured);
        files.push(strings_binary());
        files.push(bits_binary());

        let outcome = |r: std::result::Result<Mesh, Error>| match r {
            Ok(m) => Ok(m),
            Err(e) => Err(format!("{e:?}")),
        };
        let file = tempfile::tempfile().unwrap();
        let check = |bytes: &[u8], what: &str| {
            file.set_len(0).unwrap();
            file.write_all_at(bytes, 0).unwrap();
            let want = outcome(read(bytes, &mut |_| {}));
            for chunk in [1, 7, 64, 1 << 16] {
                let got = read_file(&file, bytes.len(), chunk, &mut |_| {}).expect("binary");
                assert_eq!(outcome(got), want, "{what}, chunk {chunk}");
            }
            want.is_ok()
        };
        for (f, bytes) in files.iter().enumerate() {
            assert!(check(bytes, &format!("file {f}")), "file {f} reads");
            let mut x = 0x2545_f491_4f6c_dd1d_u64 + f as u64;
            let mut next = move |n: usize| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as usize % n
            };
            for _ in 0..40 {
                let cut = next(bytes.len());
                check(&bytes[..cut], &format!("file {f} cut at {cut}"));
            }
            for _ in 0..40 {
                let mut bad = bytes.clone();
                let at = next(bytes.len());
                bad[at] = [b' ', b'\n', b'9', 0xff, 0][next(5)];
                check(&bad, &format!("file {f} with byte {at} changed"));
            }
        }
        let mut ascii = Vec::new();
        crate::io::legacy::write_ascii(&mesh, &mut ascii).unwrap();
        file.set_len(0).unwrap();
        file.write_all_at(&ascii, 0).unwrap();
        assert!(read_file(&file, ascii.len(), 64, &mut |_| {}).is_none());
    }

    /// A binary file's unit tetrahedron after its `POINTS 4 float` (or `double`) line: the
    /// points, big-endian, then its classic `CELLS` and `CELL_TYPES`.
    fn tetrahedron_after_points(f: &mut Vec<u8>, double: bool) {
        for p in [[0f64, 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
            for v in p {
                if double {
                    f.extend(v.to_be_bytes());
                } else {
                    f.extend((v as f32).to_be_bytes());
                }
            }
        }
        f.extend(b"\nCELLS 1 5\n");
        f.extend([4i32, 0, 1, 2, 3].iter().flat_map(|v| v.to_be_bytes()));
        f.extend(b"\nCELL_TYPES 1\n");
        f.extend(10i32.to_be_bytes());
    }

    /// A binary tetrahedron with strings and variants where VTK writes them — dataset field
    /// data, a point FIELD array beside a numeric one, cell pedigree ids — their lengths in
    /// headers of each size (1, 2, 4 and 8 bytes), an empty string among them.
    fn strings_binary() -> Vec<u8> {
        let mut f = b"# vtk DataFile Version 5.1\nstrings\nBINARY\nDATASET UNSTRUCTURED_GRID\n\
            FIELD FieldData 2\ncase%20name 1 2 string\n\xcapump run 7\xc0\n\
            var 1 2 variant\n6 3\n13 a%20b\nPOINTS 4 float\n"
            .to_vec();
        tetrahedron_after_points(&mut f, false);
        f.extend(b"\nPOINT_DATA 4\nFIELD FieldData 2\nlabels 1 4 string\n\x80\x46");
        f.extend([b'y'; 70]);
        f.extend(b"\x40\x00\x00\x03abc\x00\x00\x00\x00\x00\x00\x00\x02ab\xc1x");
        f.extend(b"\nt 1 4 float\n");
        f.extend([0.5f32, 1.5, 2.5, 3.5].iter().flat_map(|v| v.to_be_bytes()));
        f.extend(b"\nCELL_DATA 1\nPEDIGREE_IDS ids string\n\xc3c 0\n");
        f
    }

    /// Strings and variants are read past wherever VTK writes them, whatever their length
    /// header's size; the numeric array after them is read right.
    #[test]
    fn strings_and_variants_are_skipped() {
        let mesh = read(&strings_binary(), &mut |_| {}).unwrap();
        assert_eq!(mesh.point_data().len(), 1);
        assert_eq!(mesh.point_data()[0].name, "t");
        assert_eq!(mesh.point_data()[0].values, [0.5, 1.5, 2.5, 3.5]);
        assert!(mesh.cell_data().is_empty());
    }

    /// A binary tetrahedron with bit arrays: dataset field data, point scalars and vectors, a
    /// 2-component cell FIELD array.
    fn bits_binary() -> Vec<u8> {
        let mut f = b"# vtk DataFile Version 4.2\nbits\nBINARY\nDATASET UNSTRUCTURED_GRID\n\
            FIELD FieldData 1\nflags 1 3 bit\n\xa0\nPOINTS 4 double\n"
            .to_vec();
        tetrahedron_after_points(&mut f, true);
        f.extend(b"\nCELL_DATA 1\nFIELD FieldData 1\nmarks 2 1 bit\n\x40\n");
        f.extend(b"POINT_DATA 4\nSCALARS wet bit\nLOOKUP_TABLE default\n\x90\n");
        f.extend(b"VECTORS v bit\n\xa5\x30\n");
        f
    }

    /// Bit arrays are read as 0 and 1, high bit first, where VTK's reader keeps them.
    #[test]
    fn bits_are_read_high_bit_first() {
        let mesh = read(&bits_binary(), &mut |_| {}).unwrap();
        let [wet, v] = mesh.point_data() else {
            panic!("{:?}", mesh.point_data());
        };
        assert_eq!(
            (wet.name.as_str(), &wet.values[..]),
            ("wet", &[1., 0., 0., 1.][..])
        );
        let v_bits = [1., 0., 1., 0., 0., 1., 0., 1., 0., 0., 1., 1.];
        assert_eq!((v.components, &v.values[..]), (3, &v_bits[..]));
        assert_eq!(mesh.cell_data()[0].values, [0., 1.]);
        assert_eq!(mesh.cell_data()[0].components, 2);
    }

    #[test]
    fn classic_cell_lists_give_record_starts() {
        let list = [3i64, 7, 8, 9, 1, 5];
        let get = |i: usize| list[i];
        assert_eq!(counted_starts(2, 6, get), Ok(vec![0, 4, 6]));
        assert!(counted_starts(3, 6, get)
            .unwrap_err()
            .contains("lists 2 cells"));
        assert!(counted_starts(1, 6, get).unwrap_err().contains("use 4"));
        let bad = [5i64, 1, 2];
        assert!(counted_starts(1, 3, |i| bad[i])
            .unwrap_err()
            .contains("only 2 values remain"));
        let negative = [-1i64, 1];
        assert!(counted_starts(1, 2, |i| negative[i]).is_err());
    }
}
