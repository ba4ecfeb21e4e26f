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
//! without IBLANK; the layout is the one whose prediction equals the file's size exactly.
//!
//! **Bytes after the data.** Where no prediction equals the size, a layout whose data the file
//! holds with bytes after it (padding that Fortran writers and tools leave) is taken when the
//! layout does not rest on the size alone, as VTK's `vtkMultiBlockPLOT3DReader` takes it:
//! its record markers hold every record's length, or it is a Q file read in its grid's byte
//! order and precision, as VTK reads a Q file with its grid file's settings, where they are
//! fewer than one block of values or 4 KiB, whichever is more (more is a file cut short in
//! another layout, not padding).
//! The bytes after are ignored, and [`Layout::trailing_bytes`] says how many. A grid file without record
//! markers has no measure of its layout but its size, so it must match exactly (VTK's
//! reader cannot tell its settings either).
//!
//! None or several layouts → an error listing what was tried and the size each expects. A
//! match that is 2-D → an error saying so (this reader takes 3-D grids only).

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

/// The detected layout of a PLOT3D whole 3-D file (grid or Q) of one or several grids.
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
    /// Whether the file starts with a grid count.
    pub grid_count: bool,
    /// Points along i, j, k of the first grid, the only one of a single-grid file (i varies
    /// fastest in every block).
    pub dims: [usize; 3],
    /// Every grid's points along i, j, k, in file order (one entry for a single grid).
    pub grids: Vec<[usize; 3]>,
    /// Byte offset of the first value after the header, past any record marker: the first
    /// grid's x block in a grid file, its four-float header (Mach, alpha, Reynolds, time) in
    /// a Q file.
    pub data_offset: usize,
    /// Bytes after the last record, ignored (see the module documentation).
    pub trailing_bytes: usize,
}

impl Layout {
    /// Number of points of all grids (checked at detection not to overflow).
    pub fn points(&self) -> usize {
        self.grids.iter().map(|d| d.iter().product::<usize>()).sum()
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
    /// What the file is called in notes: `grid file`, `Q file`.
    pub(crate) fn file_name(self) -> &'static str {
        match self {
            FileKind::Grid => "grid file",
            FileKind::Solution => "Q file",
        }
    }

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

/// Bytes after a Q file's data taken for padding (without record markers) even where they
/// are more than a block of its values: a disk block's worth, for tiny grids.
pub const MAX_PADDING: u64 = 4096;

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

/// With record markers: do the markers of every grid's records hold their lengths? (True
/// without markers: nothing to check.)
fn body_markers_agree(bytes: &[u8], c: &Candidate, kind: FileKind) -> bool {
    let h = &c.header;
    if !h.reading.markers {
        return true;
    }
    let mut pos = h.body;
    for dims in &h.grids {
        let Some(lengths) = records(kind, h.reading.ndim, dims, c.precision, c.iblank) else {
            return false;
        };
        for length in lengths {
            if length > i32::MAX as u64 {
                return false;
            }
            let head = read_u32(bytes, pos, h.reading.order).map(u64::from);
            let tail = pos
                .checked_add(4 + length)
                .and_then(|at| read_u32(bytes, at, h.reading.order))
                .map(u64::from);
            if head != Some(length) || tail != Some(length) {
                return false;
            }
            pos += length + 8;
        }
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
    detect_for(bytes, kind, None)
}

/// [`detect`], for a Q file whose grid file has the layout `grid`: where its data is followed
/// by other bytes, it may be read without record markers in the grid's byte order and
/// precision, as VTK reads a Q file with its grid's settings.
pub(crate) fn detect_for(
    bytes: &[u8],
    kind: FileKind,
    grid: Option<&Layout>,
) -> Result<Layout, Error> {
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
        [one] => accept(one, kind, 0),
        [] => match padded(bytes, &all, kind, grid).as_slice() {
            [one] => accept(one, kind, one.size.map_or(0, |s| len - s)),
            [] => Err(no_match(&all, len, kind)),
            many => Err(ambiguous(many, len, kind, "with bytes after their data")),
        },
        many => Err(ambiguous(many, len, kind, "")),
    }
}

/// The error for several readings that fit a file of `len` bytes (`how` they fit).
fn ambiguous(many: &[&Candidate], len: u64, kind: FileKind, how: &str) -> Error {
    let how = if how.is_empty() {
        String::new()
    } else {
        format!(" {how}")
    };
    ReadError::new(
        kind.format(),
        0,
        format!(
            "ambiguous layout: the file's {len} bytes fit {} readings{how}: {}",
            many.len(),
            many.iter()
                .map(|c| c.describe())
                .collect::<Vec<_>>()
                .join("; ")
        ),
    )
    .into()
}

/// The readings whose data the file holds with bytes after it, where the reading does not
/// rest on the file's size: its record markers hold every record's length, or (a Q file)
/// it has the byte order, precision and grid count of its grid's layout `grid`, without
/// markers as the grid has none, and fewer bytes after its data than one block of values
/// (a variable of its smallest grid) or [`MAX_PADDING`], whichever is more: padding is
/// shorter, and more is a file cut short in another layout (a Q file of `f64` values for an
/// `f32` grid) rather than padding.
fn padded<'c>(
    bytes: &[u8],
    all: &'c [Candidate],
    kind: FileKind,
    grid: Option<&Layout>,
) -> Vec<&'c Candidate> {
    let len = bytes.len() as u64;
    let as_its_grid = |c: &Candidate| {
        let r = &c.header.reading;
        let block = c.header.grids.iter().map(|d| d[0] * d[1] * d[2]).min();
        let block = block.map_or(0, |n| n.saturating_mul(c.precision.bytes() as u64));
        let block = block.max(MAX_PADDING);
        let padding = c.size.map_or(0, |s| len - s) < block;
        kind == FileKind::Solution
            && r.ndim == 3
            && padding
            && grid.is_some_and(|g| {
                !g.record_markers
                    && !r.markers
                    && g.byte_order == r.order
                    && g.precision == c.precision
                    && g.grid_count == r.count
            })
    };
    all.iter()
        .filter(|c| c.size.is_some_and(|s| s < len))
        .filter(|c| {
            (c.header.reading.markers && body_markers_agree(bytes, c, kind)) || as_its_grid(c)
        })
        .collect()
}

fn accept(c: &Candidate, kind: FileKind, trailing: u64) -> Result<Layout, Error> {
    let format = kind.format();
    let h = &c.header;
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
    let to_usize = |v: u64| usize::try_from(v).ok();
    let too_large =
        || -> Error { ReadError::new(format, 0, "dimensions too large for this machine").into() };
    let grids = h
        .grids
        .iter()
        .map(|d| {
            let [ni, nj, nk] = d.map(to_usize);
            Some([ni?, nj?, nk?])
        })
        .collect::<Option<Vec<[usize; 3]>>>()
        .ok_or_else(too_large)?;
    let (Some(mut data_offset), Some(trailing_bytes)) = (to_usize(h.body), to_usize(trailing))
    else {
        return Err(too_large());
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
        dims: grids.first().copied().unwrap_or([0; 3]),
        grids,
        data_offset,
        trailing_bytes,
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
        // The 3-D layout with the least bytes after its data, the one padding would leave.
        let nearest = all
            .iter()
            .filter(|c| c.header.reading.ndim == 3)
            .filter_map(|c| c.size.filter(|&s| s < len).map(|s| (s, c)))
            .max_by_key(|&(s, _)| s);
        let why = match (kind, nearest) {
            (FileKind::Grid, Some((size, c))) => format!(
                "; a grid file without record markers has no measure of its layout but its \
                 size, so bytes after its data are not told from a larger layout's (with \
                 record markers they are ignored); if its last {} bytes are padding, it \
                 reads as {}, a file of {size} bytes (truncate -s {size} FILE)",
                len - size,
                c.variant()
            ),
            _ => String::new(),
        };
        format!("the file has {len} bytes, which matches no layout{why}; expected: {tried}")
    };
    ReadError::new(kind.format(), len, message).into()
}
