//! Layout detection for PLOT3D grid and Q files: byte order, precision, IBLANK, Fortran
//! record markers, a leading grid count, and the dimensions, all found from the header and the
//! file's size alone.
//!
//! Every reading of the header is tried — big- and little-endian; with and without Fortran
//! unformatted record markers (a 4-byte record length before and after each record); with and
//! without a leading grid count; 3-D and 2-D. A reading is *plausible* when its dimensions and
//! grid count lie in `1..=`[`MAX_DIMENSION`] (2²⁴), the file can hold that many grids'
//! dimensions, and its record markers (if any) hold the lengths the records must have. Each plausible
//! reading predicts a file size for every precision (`f32`, `f64`) and, for grids, with and
//! without IBLANK; the layout is the one whose prediction equals the file's size exactly. None
//! or several → an error listing what was tried and the size each expects. A match that is 2-D
//! or has more than one grid → an error saying so (this reader takes 3-D single grids only).

use crate::error::{Error, ReadError};

/// Byte order of a PLOT3D file's integers and floats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ByteOrder {
    /// Most significant byte first (the classic NASA / VTK test files).
    Big,
    /// Least significant byte first (files written on x86 without conversion).
    Little,
}

/// Floating-point precision of a PLOT3D file's coordinates or solution values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Precision {
    /// 4-byte IEEE floats.
    F32,
    /// 8-byte IEEE floats.
    F64,
}

impl Precision {
    /// Bytes per value: 4 or 8.
    pub fn bytes(self) -> usize {
        match self {
            Precision::F32 => 4,
            Precision::F64 => 8,
        }
    }
}

/// The detected layout of a PLOT3D whole, single-grid, 3-D file (grid or Q).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Byte order of every integer and float.
    pub byte_order: ByteOrder,
    /// Precision of the floats (IBLANK values are always 4-byte integers).
    pub precision: Precision,
    /// Whether an IBLANK block (one `i32` per point) follows the coordinates. Always `false`
    /// for Q files.
    pub iblank: bool,
    /// Whether records are wrapped in Fortran unformatted record markers (4-byte lengths).
    pub record_markers: bool,
    /// Whether the file starts with a grid count (which must be 1).
    pub grid_count: bool,
    /// Points along i, j, k (i varies fastest in every block).
    pub dims: [usize; 3],
    /// Byte offset of the first value after the header, past any record marker: the x block
    /// of a grid, the four-float header (Mach, alpha, Reynolds, time) of a Q file.
    pub data_offset: usize,
}

impl Layout {
    /// Number of points, `dims[0] · dims[1] · dims[2]` (checked at detection not to overflow).
    pub fn points(&self) -> usize {
        self.dims.iter().product()
    }
}

/// Which of the two PLOT3D files is being read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum FileKind {
    /// The `xyz` grid file: coordinates, then IBLANK maybe.
    Grid,
    /// The `q` solution file: four floats, then density, momentum and energy per point.
    Solution,
}

impl FileKind {
    /// The `format` of the errors this file kind reports.
    pub(crate) fn format(self) -> &'static str {
        match self {
            FileKind::Grid => "PLOT3D grid",
            FileKind::Solution => "PLOT3D Q",
        }
    }
}

/// One way of reading a header.
#[derive(Clone, Copy, Debug)]
struct Reading {
    order: ByteOrder,
    markers: bool,
    count: bool,
    ndim: usize,
}

impl Reading {
    fn describe(&self) -> String {
        format!(
            "{}, {}, {}{}-D",
            match self.order {
                ByteOrder::Big => "big-endian",
                ByteOrder::Little => "little-endian",
            },
            if self.markers {
                "record markers"
            } else {
                "no record markers"
            },
            if self.count { "grid count, " } else { "" },
            self.ndim
        )
    }
}

/// A plausible header: the grids' dimensions (a 2-D grid has `k = 1`) and where the body starts.
#[derive(Clone, Debug)]
struct Header {
    reading: Reading,
    grids: Vec<[u64; 3]>,
    body: u64,
}

impl Header {
    fn dims_text(&self) -> String {
        let one = |d: &[u64; 3]| {
            d[..self.reading.ndim]
                .iter()
                .map(u64::to_string)
                .collect::<Vec<_>>()
                .join("×")
        };
        match self.grids.as_slice() {
            [d] => one(d),
            many if many.len() <= 3 => format!(
                "{} grids {}",
                many.len(),
                many.iter().map(one).collect::<Vec<_>>().join(", ")
            ),
            many => format!("{} grids", many.len()),
        }
    }
}

/// A reading's prediction for one precision and IBLANK choice.
#[derive(Clone, Debug)]
struct Candidate {
    header: Header,
    precision: Precision,
    iblank: bool,
    /// Which reading of the header this is (candidates of one reading are adjacent).
    reading_index: usize,
    /// `None` when the size overflows `u64`.
    size: Option<u64>,
}

impl Candidate {
    fn variant(&self) -> String {
        format!(
            "{}{}",
            match self.precision {
                Precision::F32 => "f32",
                Precision::F64 => "f64",
            },
            if self.iblank { " + IBLANK" } else { "" }
        )
    }

    fn describe(&self) -> String {
        format!(
            "{} {}, {}",
            self.header.reading.describe(),
            self.header.dims_text(),
            self.variant()
        )
    }

    fn size_text(&self) -> String {
        match self.size {
            Some(s) => format!("{s} bytes"),
            None => "over 2^64 bytes".to_string(),
        }
    }
}

fn read_u32(bytes: &[u8], pos: u64, order: ByteOrder) -> Option<u32> {
    let start = usize::try_from(pos).ok()?;
    let word: [u8; 4] = bytes.get(start..start.checked_add(4)?)?.try_into().ok()?;
    Some(match order {
        ByteOrder::Big => u32::from_be_bytes(word),
        ByteOrder::Little => u32::from_le_bytes(word),
    })
}

/// The largest plausible dimension or grid count. Integers read in the wrong byte order are
/// almost always larger (a dimension of 38 read little-endian is 637,534,208) and so are the
/// bits of most floats read as integers; no real grid has 16 million points along one index.
pub const MAX_DIMENSION: u64 = 1 << 24;

/// An integer in `1..=MAX_DIMENSION` at `pos`.
fn read_positive(bytes: &[u8], pos: u64, order: ByteOrder) -> Option<u64> {
    let v = u64::from(read_u32(bytes, pos, order)?);
    (1..=MAX_DIMENSION).contains(&v).then_some(v)
}

/// Reads a header the given way; `None` when the integers or markers make no sense that way.
fn parse_header(bytes: &[u8], reading: Reading) -> Option<Header> {
    let order = reading.order;
    let ndim = reading.ndim as u64;
    let len = bytes.len() as u64;
    let mut pos = 0u64;
    let mut ngrids = 1u64;
    if reading.count {
        if reading.markers {
            (read_u32(bytes, pos, order)? == 4).then_some(())?;
            ngrids = read_positive(bytes, pos + 4, order)?;
            (read_u32(bytes, pos + 8, order)? == 4).then_some(())?;
            pos += 12;
        } else {
            ngrids = read_positive(bytes, pos, order)?;
            pos += 4;
        }
    }
    // Every grid's dimensions need 4·ndim bytes of header: a count the file cannot hold is not
    // a count (this also bounds the allocation below by the file's size).
    let dims_bytes = ngrids.checked_mul(4 * ndim)?;
    if dims_bytes > len.saturating_sub(pos) {
        return None;
    }
    if reading.markers {
        (u64::from(read_u32(bytes, pos, order)?) == dims_bytes).then_some(())?;
        pos += 4;
    }
    let mut grids = Vec::with_capacity(ngrids as usize);
    for _ in 0..ngrids {
        let mut d = [1u64; 3];
        for v in d.iter_mut().take(reading.ndim) {
            *v = read_positive(bytes, pos, order)?;
            pos += 4;
        }
        grids.push(d);
    }
    if reading.markers {
        (u64::from(read_u32(bytes, pos, order)?) == dims_bytes).then_some(())?;
        pos += 4;
    }
    Some(Header {
        reading,
        grids,
        body: pos,
    })
}

/// Values per point of a solution file: density, the momenta, energy.
fn solution_variables(ndim: usize) -> u64 {
    ndim as u64 + 2
}

/// The records of one grid's body, in bytes (without markers).
fn records(
    kind: FileKind,
    ndim: usize,
    dims: &[u64; 3],
    precision: Precision,
    iblank: bool,
) -> Option<Vec<u64>> {
    let n = dims[0].checked_mul(dims[1])?.checked_mul(dims[2])?;
    let s = precision.bytes() as u64;
    Some(match kind {
        FileKind::Grid => {
            let coords = n.checked_mul(ndim as u64)?.checked_mul(s)?;
            let blank = if iblank { n.checked_mul(4)? } else { 0 };
            vec![coords.checked_add(blank)?]
        }
        FileKind::Solution => vec![
            4 * s,
            n.checked_mul(solution_variables(ndim))?.checked_mul(s)?,
        ],
    })
}

fn predicted_size(
    kind: FileKind,
    header: &Header,
    precision: Precision,
    iblank: bool,
) -> Option<u64> {
    let marker_bytes = if header.reading.markers { 8 } else { 0 };
    let mut total = header.body;
    for dims in &header.grids {
        for record in records(kind, header.reading.ndim, dims, precision, iblank)? {
            total = total.checked_add(record)?.checked_add(marker_bytes)?;
        }
    }
    Some(total)
}

/// For a single grid with record markers: do the body's markers hold the record lengths?
fn body_markers_agree(bytes: &[u8], c: &Candidate, kind: FileKind) -> bool {
    let h = &c.header;
    if !h.reading.markers || h.grids.len() != 1 {
        return true;
    }
    let Some(lengths) = records(kind, h.reading.ndim, &h.grids[0], c.precision, c.iblank) else {
        return false;
    };
    let mut pos = h.body;
    for length in lengths {
        let expected = Some(length).filter(|&l| l <= i32::MAX as u64);
        let Some(expected) = expected else {
            return false;
        };
        let head = read_u32(bytes, pos, h.reading.order).map(u64::from);
        let tail = read_u32(bytes, pos + 4 + length, h.reading.order).map(u64::from);
        if head != Some(expected) || tail != Some(expected) {
            return false;
        }
        pos += length + 8;
    }
    true
}

/// Every plausible reading's predictions.
fn candidates(bytes: &[u8], kind: FileKind) -> Vec<Candidate> {
    let mut out = Vec::new();
    for ndim in [3, 2] {
        for order in [ByteOrder::Big, ByteOrder::Little] {
            for markers in [false, true] {
                for count in [false, true] {
                    let reading = Reading {
                        order,
                        markers,
                        count,
                        ndim,
                    };
                    let Some(header) = parse_header(bytes, reading) else {
                        continue;
                    };
                    let reading_index = out.len();
                    for precision in [Precision::F32, Precision::F64] {
                        let blanks: &[bool] = match kind {
                            FileKind::Grid => &[false, true],
                            FileKind::Solution => &[false],
                        };
                        for &iblank in blanks {
                            let size = predicted_size(kind, &header, precision, iblank);
                            out.push(Candidate {
                                header: header.clone(),
                                precision,
                                iblank,
                                reading_index,
                                size,
                            });
                        }
                    }
                }
            }
        }
    }
    out
}

/// Detects the layout of a grid (`kind = Grid`) or Q file. See the module documentation.
pub(crate) fn detect(bytes: &[u8], kind: FileKind) -> Result<Layout, Error> {
    let format = kind.format();
    let len = bytes.len() as u64;
    if len < 12 {
        return Err(ReadError::new(
            format,
            len,
            format!(
                "the file has {len} bytes, expected at least 12 for a PLOT3D header (three dimensions)"
            ),
        )
        .into());
    }
    let all = candidates(bytes, kind);
    if all.is_empty() {
        return Err(ReadError::new(
            format,
            0,
            format!(
                "no plausible PLOT3D header: the leading integers are not dimensions from 1 to \
                 {MAX_DIMENSION} in either byte order, with or without record markers or a grid \
                 count (the file has {len} bytes)"
            ),
        )
        .into());
    }
    let matches: Vec<&Candidate> = all
        .iter()
        .filter(|c| c.size == Some(len) && body_markers_agree(bytes, c, kind))
        .collect();
    match matches.as_slice() {
        [one] => accept(one, kind),
        [] => Err(no_match(&all, len, kind)),
        many => Err(ReadError::new(
            format,
            0,
            format!(
                "ambiguous layout: the file's {len} bytes fit {} readings: {}",
                many.len(),
                many.iter()
                    .map(|c| c.describe())
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        )
        .into()),
    }
}

fn accept(c: &Candidate, kind: FileKind) -> Result<Layout, Error> {
    let format = kind.format();
    let h = &c.header;
    if h.grids.len() > 1 {
        return Err(ReadError::new(
            format,
            0,
            format!(
                "multi-grid PLOT3D files are not supported: {} grids ({})",
                h.grids.len(),
                c.describe()
            ),
        )
        .into());
    }
    if h.reading.ndim != 3 {
        return Err(ReadError::new(
            format,
            0,
            format!(
                "2-D PLOT3D files are not supported ({}); only 3-D whole grids",
                c.describe()
            ),
        )
        .into());
    }
    let [ni, nj, nk] = h.grids.first().copied().unwrap_or([0; 3]);
    let to_usize = |v: u64| usize::try_from(v).ok();
    let (Some(ni), Some(nj), Some(nk), Some(mut data_offset)) =
        (to_usize(ni), to_usize(nj), to_usize(nk), to_usize(h.body))
    else {
        return Err(ReadError::new(format, 0, "dimensions too large for this machine").into());
    };
    if h.reading.markers {
        data_offset += 4;
    }
    Ok(Layout {
        byte_order: h.reading.order,
        precision: c.precision,
        iblank: c.iblank,
        record_markers: h.reading.markers,
        grid_count: h.reading.count,
        dims: [ni, nj, nk],
        data_offset,
    })
}

fn no_match(all: &[Candidate], len: u64, kind: FileKind) -> Error {
    // One entry per reading of the header, with the size each precision / IBLANK choice expects.
    let tried = all
        .chunk_by(|a, b| a.reading_index == b.reading_index)
        .map(|group| {
            let sizes = group
                .iter()
                .map(|c| format!("{} {}", c.variant(), c.size_text()))
                .collect::<Vec<_>>()
                .join(", ");
            format!(
                "{} {}: {sizes}",
                group[0].header.reading.describe(),
                group[0].header.dims_text()
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    let truncated = all.iter().all(|c| !matches!(c.size, Some(s) if s <= len));
    let message = if truncated {
        format!(
            "truncated file: it has {len} bytes, fewer than every layout its header allows; \
             expected: {tried}"
        )
    } else {
        format!("the file has {len} bytes, which matches no layout; expected: {tried}")
    };
    ReadError::new(kind.format(), len, message).into()
}
