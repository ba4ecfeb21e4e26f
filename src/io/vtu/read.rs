//! The VTU reader: walks the XML structure (stopping at raw appended data), collects each
//! piece's arrays, decodes them and assembles a validated [`Mesh`].

use std::borrow::Cow;
use std::ops::Range;

use glam::DVec3;

#[cfg(unix)]
use super::decode::FileSource;
use super::decode::{
    ascii_f64, ascii_i64, read_binary, skip_binary, Base64Source, Compressor, Layout, RawSource,
    Source,
};
use crate::io::elements::{is_integer, to_f64, to_i64, to_tuples, Integers, ScalarType};

use super::xml::{attr, check_file_type, is_blank, Attr, Event, OpenElements, Scanner};
use super::FORMAT;
use crate::error::{Error, ReadError};
use crate::io::empty::{self, drop_tuples};
use crate::io::ghost::{drop_ghost_cells, Blanking};
use crate::mesh::{cells_from_ids, ConvertedCells, DataArray, MeshParts, OffsetStyle};
use crate::Mesh;

fn err(offset: usize, message: impl Into<String>) -> ReadError {
    ReadError::new(FORMAT, offset as u64, message)
}

/// Where an array's data is.
#[derive(Clone, Debug, PartialEq, Eq)]
enum DataFormat {
    Ascii,
    Binary,
    Appended(u64),
}

/// A `DataArray` element as found in the XML.
#[derive(Clone, Debug)]
struct ArrayDesc {
    name: String,
    /// `None` for types that are not numbers (strings, bits, unknown names); of those, bit
    /// arrays are read as 0 and 1 and the others skipped.
    ty: Option<ScalarType>,
    type_name: String,
    components: usize,
    format: DataFormat,
    /// Byte ranges of the element's own character data.
    text: Vec<Range<usize>>,
    /// Byte offset of the start tag.
    at: usize,
}

/// The sections of a piece an array can belong to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Section {
    Points,
    Cells,
    PointData,
    CellData,
}

#[derive(Debug, Default)]
struct PieceDesc {
    points: usize,
    cells: usize,
    /// An image's or a structured grid's piece's `Extent` (`None` for an unstructured grid's).
    extent: Option<[i64; 6]>,
    at: usize,
    coords: Option<ArrayDesc>,
    cell_arrays: Vec<ArrayDesc>,
    point_data: Vec<ArrayDesc>,
    cell_data: Vec<ArrayDesc>,
    active_point: Option<String>,
    active_cell: Option<String>,
}

/// The appended-data block.
#[derive(Clone, Copy, Debug)]
enum Appended<'a> {
    /// Raw bytes from file offset `start` to the end of the file.
    Raw { data: RawData<'a>, start: usize },
    /// Base64 text from file offset `start`.
    Base64 { text: &'a [u8], start: usize },
}

/// Where raw appended bytes are: in memory with the rest of the file, or left in the file
/// and read an array at a time ([`read_file_parts`]).
#[derive(Clone, Copy, Debug)]
enum RawData<'a> {
    Bytes(&'a [u8]),
    #[cfg(unix)]
    File {
        file: &'a std::fs::File,
        len: usize,
    },
}

impl<'a> RawData<'a> {
    fn len(&self) -> usize {
        match self {
            RawData::Bytes(data) => data.len(),
            #[cfg(unix)]
            RawData::File { len, .. } => *len,
        }
    }

    /// A source over the data, which starts at file offset `start`, reading from `pos`.
    fn source(self, start: usize, pos: usize) -> Box<dyn Source<'a> + 'a> {
        match self {
            RawData::Bytes(data) => Box::new(RawSource::new(data, start, pos)),
            #[cfg(unix)]
            RawData::File { file, len } => Box::new(FileSource::new(file, start, len, pos)),
        }
    }
}

/// The dataset types the XML walker reads: unstructured and structured grids for meshes,
/// images (such as a render's depth image) for their point arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum XmlDataset {
    /// `UnstructuredGrid` (`.vtu`).
    UnstructuredGrid,
    /// `StructuredGrid` (`.vts`): pieces of an extent, points given, cells implied.
    StructuredGrid,
    /// `ImageData` (`.vti`).
    ImageData,
}

impl XmlDataset {
    /// The `VTKFile` type and the dataset element's name.
    fn element(self) -> &'static str {
        match self {
            XmlDataset::UnstructuredGrid => "UnstructuredGrid",
            XmlDataset::StructuredGrid => "StructuredGrid",
            XmlDataset::ImageData => "ImageData",
        }
    }

    fn extension(self) -> &'static str {
        match self {
            XmlDataset::UnstructuredGrid => ".vtu",
            XmlDataset::StructuredGrid => ".vts",
            XmlDataset::ImageData => ".vti",
        }
    }
}

struct Parsed<'a> {
    layout: Layout,
    /// An image's `WholeExtent` (`None` for an unstructured grid).
    whole_extent: Option<[i64; 6]>,
    pieces: Vec<PieceDesc>,
    appended: Option<Appended<'a>>,
    /// `(offset, tag offset)` of every appended array anywhere in the file.
    appended_arrays: Vec<(u64, usize)>,
    /// Where the XML resumes after a raw appended block, with the open elements.
    resume: Vec<String>,
}

fn parse_usize(attrs: &[Attr<'_>], name: &str, tag: &str, at: usize) -> Result<usize, ReadError> {
    let v = attr(attrs, name).ok_or_else(|| err(at, format!("<{tag}> has no {name}")))?;
    v.trim()
        .parse::<usize>()
        .map_err(|_| err(at, format!("<{tag}> {name}=\"{v}\" is not a count")))
}

/// An image extent attribute: six integers, `lo ≤ hi` on each axis.
fn parse_extent(
    attrs: &[Attr<'_>],
    name: &str,
    tag: &str,
    at: usize,
) -> Result<[i64; 6], ReadError> {
    let v = attr(attrs, name).ok_or_else(|| err(at, format!("<{tag}> has no {name}")))?;
    let bad = || {
        err(
            at,
            format!("<{tag}> {name}=\"{v}\" is not six integers, low ≤ high"),
        )
    };
    let values: Vec<i64> = v
        .split_ascii_whitespace()
        .map(|x| x.parse::<i64>().map_err(|_| bad()))
        .collect::<Result<_, _>>()?;
    let extent: [i64; 6] = values.try_into().map_err(|_| bad())?;
    if extent[0] > extent[1] || extent[2] > extent[3] || extent[4] > extent[5] {
        return Err(bad());
    }
    Ok(extent)
}

/// A structured piece's `Extent`: six integers; an empty extent (a high end below its low
/// end on some axis, as writers give a piece with nothing in it) holds no points.
fn parse_piece_extent(attrs: &[Attr<'_>], at: usize) -> Result<PieceDesc, ReadError> {
    let v = attr(attrs, "Extent").ok_or_else(|| err(at, "<Piece> has no Extent"))?;
    let values: Option<Vec<i64>> = v
        .split_ascii_whitespace()
        .map(|x| x.parse::<i64>().ok())
        .collect();
    let extent: [i64; 6] = values
        .and_then(|v| v.try_into().ok())
        .ok_or_else(|| err(at, format!("<Piece> Extent=\"{v}\" is not six integers")))?;
    if extent[0] > extent[1] || extent[2] > extent[3] || extent[4] > extent[5] {
        return Ok(PieceDesc {
            at,
            ..PieceDesc::default()
        });
    }
    let too_many = || err(at, "<Piece> Extent holds too many points");
    let points = extent_points(&extent).ok_or_else(too_many)?;
    // As VTK counts a structured extent's cells: a flat axis counts once.
    let cells = extent.chunks_exact(2).try_fold(1usize, |n, e| {
        let span = usize::try_from(e[1] - e[0]).ok()?.max(1);
        n.checked_mul(span)
    });
    Ok(PieceDesc {
        points,
        cells: cells.ok_or_else(too_many)?,
        extent: Some(extent),
        at,
        ..PieceDesc::default()
    })
}

/// The points of an image extent (`None` if they do not fit a `usize`).
fn extent_points(extent: &[i64; 6]) -> Option<usize> {
    extent.chunks_exact(2).try_fold(1usize, |n, e| {
        let span = usize::try_from(e[1].checked_sub(e[0])?.checked_add(1)?).ok()?;
        n.checked_mul(span)
    })
}

fn file_header(attrs: &[Attr<'_>], at: usize, dataset: XmlDataset) -> Result<Layout, ReadError> {
    check_file_type(attrs, dataset.element()).map_err(|what| {
        err(
            at,
            format!(
                "the file holds {what}; only {} ({}) is supported",
                dataset.element(),
                dataset.extension()
            ),
        )
    })?;
    let big_endian = match attr(attrs, "byte_order") {
        None | Some("LittleEndian") => false,
        Some("BigEndian") => true,
        Some(o) => return Err(err(at, format!("unknown byte_order \"{o}\""))),
    };
    let header64 = match attr(attrs, "header_type") {
        None | Some("UInt32") => false,
        Some("UInt64") => true,
        Some(h) => return Err(err(at, format!("unknown header_type \"{h}\""))),
    };
    let compressor = match attr(attrs, "compressor") {
        None | Some("") => None,
        Some(c) => Some(Compressor::parse(c).ok_or_else(|| {
            err(
                at,
                format!(
                    "compressor \"{c}\" is not supported (vtkZLibDataCompressor, \
                     vtkLZ4DataCompressor and vtkLZMADataCompressor are)"
                ),
            )
        })?),
    };
    Ok(Layout {
        big_endian,
        header64,
        compressor,
    })
}

fn array_desc(attrs: &[Attr<'_>], at: usize) -> Result<ArrayDesc, ReadError> {
    let type_name = attr(attrs, "type").unwrap_or("").to_string();
    let components = match attr(attrs, "NumberOfComponents") {
        None => 1,
        Some(c) => c
            .trim()
            .parse::<usize>()
            .map_err(|_| err(at, format!("NumberOfComponents=\"{c}\" is not a count")))?,
    };
    let format = match attr(attrs, "format") {
        Some("ascii") => DataFormat::Ascii,
        Some("binary") => DataFormat::Binary,
        Some("appended") => {
            let o =
                attr(attrs, "offset").ok_or_else(|| err(at, "appended DataArray has no offset"))?;
            DataFormat::Appended(
                o.trim()
                    .parse::<u64>()
                    .map_err(|_| err(at, format!("offset=\"{o}\" is not an offset")))?,
            )
        }
        Some(f) => return Err(err(at, format!("unknown DataArray format \"{f}\""))),
        None => return Err(err(at, "DataArray has no format")),
    };
    Ok(ArrayDesc {
        name: attr(attrs, "Name").unwrap_or("").to_string(),
        ty: ScalarType::parse(&type_name),
        type_name,
        components,
        format,
        text: Vec::new(),
        at,
    })
}

/// Walks the XML part of a file holding `dataset`.
fn parse_structure(bytes: &[u8], dataset: XmlDataset) -> Result<Parsed<'_>, ReadError> {
    let grid = dataset.element();
    let mut whole_extent = None;
    let mut sc = Scanner::document(bytes);
    let mut open = OpenElements::new(FORMAT);
    let mut layout = None;
    let mut pieces: Vec<PieceDesc> = Vec::new();
    let mut section: Option<Section> = None;
    // The DataArray being read, and the depth of open elements it lives at.
    let mut current: Option<(ArrayDesc, Section, usize)> = None;
    let mut appended_arrays = Vec::new();
    let mut seen_grid = false;
    loop {
        match sc.next_event()? {
            Event::Eof => {
                open.end(bytes)?;
                if layout.is_none() {
                    return Err(err(0, "not a VTK XML file: no <VTKFile> element"));
                }
                break;
            }
            Event::Text(range) => {
                open.text(bytes, &range)?;
                if let Some((desc, _, depth)) = current.as_mut() {
                    if open.names().len() == *depth && !is_blank(&bytes[range.clone()]) {
                        desc.text.push(range);
                    }
                }
            }
            Event::End { name, offset } => {
                open.close(name, offset)?;
                if current
                    .as_ref()
                    .is_some_and(|(_, _, d)| open.names().len() + 1 == *d)
                {
                    if let Some((desc, sec, _)) = current.take() {
                        store(&mut pieces, sec, desc);
                    }
                }
                if matches!(name, "Points" | "Cells" | "PointData" | "CellData")
                    && open.innermost() == Some("Piece")
                {
                    section = None;
                }
                if open.names().is_empty() {
                    // The root element is closed: nothing after it matters but white space.
                    loop {
                        match sc.next_event()? {
                            Event::Eof => break,
                            Event::Text(r) if is_blank(&bytes[r.clone()]) => {}
                            _ => return Err(err(sc.pos(), "content after the closing </VTKFile>")),
                        }
                    }
                    break;
                }
            }
            Event::Start {
                name,
                attrs,
                empty,
                offset,
                end,
            } => {
                let parent = open.innermost();
                match (parent, name) {
                    (None, "VTKFile") => layout = Some(file_header(&attrs, offset, dataset)?),
                    (None, other) => {
                        return Err(err(
                            offset,
                            format!("not a VTK XML file: the root element is <{other}>"),
                        ))
                    }
                    (Some("VTKFile"), name) if name == grid => {
                        seen_grid = true;
                        if dataset == XmlDataset::ImageData {
                            whole_extent = Some(parse_extent(&attrs, "WholeExtent", name, offset)?);
                        }
                    }
                    (Some(parent), "Piece") if parent == grid => pieces.push(match dataset {
                        XmlDataset::UnstructuredGrid => PieceDesc {
                            points: parse_usize(&attrs, "NumberOfPoints", "Piece", offset)?,
                            cells: parse_usize(&attrs, "NumberOfCells", "Piece", offset)?,
                            at: offset,
                            ..PieceDesc::default()
                        },
                        XmlDataset::StructuredGrid => parse_piece_extent(&attrs, offset)?,
                        XmlDataset::ImageData => {
                            let extent = parse_extent(&attrs, "Extent", "Piece", offset)?;
                            PieceDesc {
                                points: extent_points(&extent).ok_or_else(|| {
                                    err(offset, "<Piece> Extent holds too many points")
                                })?,
                                extent: Some(extent),
                                at: offset,
                                ..PieceDesc::default()
                            }
                        }
                    }),
                    (Some("Piece"), "Points") => section = Some(Section::Points),
                    (Some("Piece"), "Cells") => section = Some(Section::Cells),
                    (Some("Piece"), "PointData") => {
                        section = Some(Section::PointData);
                        if let Some(p) = pieces.last_mut() {
                            p.active_point = attr(&attrs, "Scalars").map(str::to_string);
                        }
                    }
                    (Some("Piece"), "CellData") => {
                        section = Some(Section::CellData);
                        if let Some(p) = pieces.last_mut() {
                            p.active_cell = attr(&attrs, "Scalars").map(str::to_string);
                        }
                    }
                    (Some("VTKFile"), "AppendedData") => {
                        let Some(layout) = layout else {
                            return Err(err(offset, "<AppendedData> outside <VTKFile>"));
                        };
                        let encoding = attr(&attrs, "encoding").unwrap_or("");
                        let mut pos = end;
                        while bytes.get(pos).is_some_and(|b| b.is_ascii_whitespace()) {
                            pos += 1;
                        }
                        if empty || bytes.get(pos) != Some(&b'_') {
                            return Err(err(pos, "expected '_' at the start of the appended data"));
                        }
                        let start = pos + 1;
                        let rest = bytes.get(start..).unwrap_or(&[]);
                        let mut resume: Vec<String> =
                            open.names().iter().map(|s| s.to_string()).collect();
                        resume.push("AppendedData".into());
                        let appended = match encoding {
                            "raw" => Appended::Raw {
                                data: RawData::Bytes(rest),
                                start,
                            },
                            "base64" => {
                                let len =
                                    rest.iter().position(|&b| b == b'<').unwrap_or(rest.len());
                                Appended::Base64 {
                                    text: &rest[..len],
                                    start,
                                }
                            }
                            e => {
                                return Err(err(
                                    offset,
                                    format!("unknown AppendedData encoding \"{e}\""),
                                ))
                            }
                        };
                        if !seen_grid {
                            return Err(err(offset, format!("no <{grid}> element")));
                        }
                        return Ok(Parsed {
                            layout,
                            whole_extent,
                            pieces,
                            appended: Some(appended),
                            appended_arrays,
                            resume,
                        });
                    }
                    (Some(p), "DataArray") => {
                        let desc = array_desc(&attrs, offset)?;
                        if let DataFormat::Appended(o) = desc.format {
                            appended_arrays.push((o, offset));
                        }
                        if let (Some(sec), "Points" | "Cells" | "PointData" | "CellData") =
                            (section, p)
                        {
                            if empty {
                                store(&mut pieces, sec, desc);
                            } else if current.is_none() {
                                current = Some((desc, sec, open.names().len() + 1));
                            }
                        }
                    }
                    (Some(_), "Array") if attr(&attrs, "format") == Some("appended") => {
                        if let Some(o) = attr(&attrs, "offset").and_then(|o| o.parse().ok()) {
                            appended_arrays.push((o, offset));
                        }
                    }
                    _ => {}
                }
                if !empty {
                    open.open(name);
                }
            }
        }
    }
    let Some(layout) = layout else {
        return Err(err(0, "not a VTK XML file: no <VTKFile> element"));
    };
    if !seen_grid {
        return Err(err(0, format!("no <{grid}> element")));
    }
    Ok(Parsed {
        layout,
        whole_extent,
        pieces,
        appended: None,
        appended_arrays,
        resume: Vec::new(),
    })
}

fn store(pieces: &mut [PieceDesc], section: Section, desc: ArrayDesc) {
    let Some(p) = pieces.last_mut() else { return };
    match section {
        Section::Points => {
            if p.coords.is_none() {
                p.coords = Some(desc);
            }
        }
        Section::Cells => p.cell_arrays.push(desc),
        Section::PointData => p.point_data.push(desc),
        Section::CellData => p.cell_data.push(desc),
    }
}

/// Decodes arrays with the file's layout and appended block.
struct Decoder<'a> {
    bytes: &'a [u8],
    layout: Layout,
    appended: Option<Appended<'a>>,
}

/// An array's element data: borrowed raw bytes, decoded bytes, or parsed ascii numbers.
enum Data<'a> {
    Bytes(Cow<'a, [u8]>),
    Text(Cow<'a, [u8]>, usize),
}

impl<'a> Decoder<'a> {
    /// The character data of an inline array (joined if split by child elements).
    fn text(&self, desc: &ArrayDesc) -> (Cow<'a, [u8]>, usize) {
        match desc.text.as_slice() {
            [] => (Cow::Borrowed(&[][..]), desc.at),
            [one] => (Cow::Borrowed(&self.bytes[one.clone()]), one.start),
            many => {
                let mut joined = Vec::new();
                for r in many {
                    joined.extend_from_slice(&self.bytes[r.clone()]);
                    joined.push(b' ');
                }
                (Cow::Owned(joined), many[0].start)
            }
        }
    }

    /// The element data of an array of `count` elements of its type.
    fn data(&self, desc: &ArrayDesc, ty: ScalarType, count: usize) -> Result<Data<'a>, ReadError> {
        let expected = (count as u64)
            .checked_mul(ty.size() as u64)
            .ok_or_else(|| {
                err(
                    desc.at,
                    format!("DataArray \"{}\": too many values", desc.name),
                )
            })?;
        self.data_bytes(desc, expected)
    }

    /// The character data of an ASCII array, or the `expected` bytes of a binary or appended
    /// one, decompressed.
    fn data_bytes(&self, desc: &ArrayDesc, expected: u64) -> Result<Data<'a>, ReadError> {
        let what = format!("DataArray \"{}\"", desc.name);
        match desc.format {
            DataFormat::Ascii => {
                let (text, at) = self.text(desc);
                Ok(Data::Text(text, at))
            }
            DataFormat::Binary => {
                let (text, at) = self.text(desc);
                let bytes = {
                    let mut src = Base64Source::new(&text, at, 0);
                    read_binary(&mut src, self.layout, expected, &what)?.into_owned()
                };
                Ok(Data::Bytes(Cow::Owned(bytes)))
            }
            DataFormat::Appended(offset) => {
                let (mut src, _) = self.appended_source(desc, offset)?;
                read_binary(src.as_mut(), self.layout, expected, &what).map(Data::Bytes)
            }
        }
    }

    fn appended_source(
        &self,
        desc: &ArrayDesc,
        offset: u64,
    ) -> Result<(Box<dyn Source<'a> + 'a>, usize), ReadError> {
        let Some(app) = self.appended else {
            return Err(err(
                desc.at,
                format!(
                    "DataArray \"{}\" is appended but the file has no <AppendedData>",
                    desc.name
                ),
            ));
        };
        let len = match app {
            Appended::Raw { data, .. } => data.len(),
            Appended::Base64 { text, .. } => text.len(),
        };
        let pos = usize::try_from(offset)
            .ok()
            .filter(|&o| o <= len)
            .ok_or_else(|| {
                err(
                    desc.at,
                    format!(
                    "DataArray \"{}\": offset {offset} is beyond the {len} bytes of appended data",
                    desc.name
                ),
                )
            })?;
        Ok(match app {
            Appended::Raw { data, start } => (data.source(start, pos), start),
            Appended::Base64 { text, start } => {
                (Box::new(Base64Source::new(text, start, pos)), start)
            }
        })
    }

    /// The array's element type, which must be a numeric one.
    fn value_type(desc: &ArrayDesc) -> Result<ScalarType, ReadError> {
        desc.ty.ok_or_else(|| {
            err(
                desc.at,
                format!(
                    "DataArray \"{}\" has unsupported type \"{}\"",
                    desc.name, desc.type_name
                ),
            )
        })
    }

    /// `count` values of a `type="Bit"` array as 0 and 1, as VTK's XML readers give them: in
    /// an ASCII array, one number a value (any but 0 is 1); in binary and appended data,
    /// `⌈count / 8⌉` bytes, the first value in a byte's highest bit, the tuples' components in
    /// turn.
    fn bits(&self, desc: &ArrayDesc, count: usize) -> Result<Vec<f64>, ReadError> {
        let what = format!("DataArray \"{}\"", desc.name);
        match self.data_bytes(desc, (count as u64).div_ceil(8))? {
            Data::Bytes(b) => Ok((0..count)
                .map(|i| f64::from((b[i / 8] >> (7 - i % 8)) & 1))
                .collect()),
            Data::Text(t, at) => Ok(ascii_f64(&t, at, count, &what)?
                .into_iter()
                .map(|v| if v == 0.0 { 0.0 } else { 1.0 })
                .collect()),
        }
    }

    fn f64s(&self, desc: &ArrayDesc, count: usize) -> Result<Vec<f64>, ReadError> {
        let ty = Self::value_type(desc)?;
        match self.data(desc, ty, count)? {
            Data::Bytes(b) => Ok(to_f64(&b, ty, self.layout.big_endian)),
            Data::Text(t, at) => ascii_f64(&t, at, count, &format!("DataArray \"{}\"", desc.name)),
        }
    }

    /// The array's element type, which must be an integer one.
    fn integer_type(desc: &ArrayDesc) -> Result<ScalarType, ReadError> {
        desc.ty.filter(|&t| is_integer(t)).ok_or_else(|| {
            err(
                desc.at,
                format!(
                    "DataArray \"{}\" must have an integer type, not \"{}\"",
                    desc.name, desc.type_name
                ),
            )
        })
    }

    fn i64s(&self, desc: &ArrayDesc, count: usize) -> Result<Vec<i64>, ReadError> {
        let ty = Self::integer_type(desc)?;
        match self.data(desc, ty, count)? {
            Data::Bytes(b) => Ok(to_i64(&b, ty, self.layout.big_endian)),
            Data::Text(t, at) => {
                ascii_i64(&t, at, count, ty, &format!("DataArray \"{}\"", desc.name))
            }
        }
    }

    /// `count` points from a three-component array.
    fn points(&self, desc: &ArrayDesc, count: usize) -> Result<Vec<DVec3>, ReadError> {
        let n3 = count
            .checked_mul(3)
            .ok_or_else(|| err(desc.at, "too many points"))?;
        let ty = Self::value_type(desc)?;
        Ok(match self.data(desc, ty, n3)? {
            Data::Bytes(b) => to_tuples(&b, ty, self.layout.big_endian, DVec3::from_array),
            Data::Text(t, at) => ascii_f64(&t, at, n3, &format!("DataArray \"{}\"", desc.name))?
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2]))
                .collect(),
        })
    }

    /// The cells of a piece's `connectivity` array (`len` entries) with its offsets and
    /// types, converted from the stored integers without an `i64` copy of the array.
    fn cells(
        &self,
        desc: &ArrayDesc,
        len: usize,
        offsets: &[i64],
        types: &[u8],
        points: usize,
    ) -> Result<ConvertedCells, Error> {
        let ty = Self::integer_type(desc)?;
        Ok(match self.data(desc, ty, len)? {
            Data::Bytes(b) => {
                let ids = Integers::new(&b, ty, self.layout.big_endian)
                    .ok_or_else(|| err(desc.at, "connectivity is not an integer array"))?;
                cells_from_ids(
                    ids.len(),
                    |k| ids.get(k),
                    offsets,
                    OffsetStyle::Ends,
                    0,
                    types,
                    points,
                )?
            }
            Data::Text(t, at) => {
                let what = format!("DataArray \"{}\"", desc.name);
                let ids = ascii_i64(&t, at, len, ty, &what)?;
                cells_from_ids(
                    ids.len(),
                    |k| ids[k],
                    offsets,
                    OffsetStyle::Ends,
                    0,
                    types,
                    points,
                )?
            }
        })
    }

    /// End (within the appended block) of the appended array at `offset`.
    fn appended_end(&self, offset: u64, at: usize) -> Result<usize, ReadError> {
        let Some(Appended::Raw { data, start }) = self.appended else {
            return Ok(0);
        };
        let pos = usize::try_from(offset)
            .ok()
            .filter(|&o| o <= data.len())
            .ok_or_else(|| {
                err(
                    at,
                    format!(
                        "offset {offset} is beyond the {} bytes of appended data",
                        data.len()
                    ),
                )
            })?;
        let mut src = data.source(start, pos);
        skip_binary(src.as_mut(), self.layout, "appended array")?;
        // Within the data's length (checked by the source).
        Ok((src.offset() - start as u64) as usize)
    }
}

/// Checks that after the raw appended block there is only what closes the open elements.
fn check_trailer(bytes: &[u8], from: usize, open: &[String]) -> Result<(), ReadError> {
    let mut sc = Scanner::new(bytes, from);
    let mut open: Vec<&str> = open.iter().map(String::as_str).collect();
    loop {
        match sc.next_event()? {
            Event::Text(r) if is_blank(&bytes[r.clone()]) => {}
            Event::End { name, offset } => match open.pop() {
                Some(o) if o == name => {}
                _ => {
                    return Err(err(
                        offset,
                        format!("unexpected </{name}> after the appended data"),
                    ))
                }
            },
            Event::Eof if open.is_empty() => return Ok(()),
            Event::Eof => {
                return Err(err(
                    bytes.len(),
                    format!(
                        "the file ends inside <{}> (truncated?)",
                        open.last().copied().unwrap_or("")
                    ),
                ))
            }
            _ => {
                return Err(err(
                    sc.pos(),
                    "unexpected content after the appended data (truncated or corrupt file?)",
                ))
            }
        }
    }
}

fn cell_array<'p>(piece: &'p PieceDesc, name: &str) -> Result<&'p ArrayDesc, ReadError> {
    piece
        .cell_arrays
        .iter()
        .find(|a| a.name == name)
        .ok_or_else(|| err(piece.at, format!("<Cells> has no \"{name}\" DataArray")))
}

fn data_arrays(
    dec: &Decoder<'_>,
    descs: &[ArrayDesc],
    tuples: usize,
) -> Result<Vec<DataArray>, ReadError> {
    let mut out = Vec::new();
    for d in descs {
        let bits = d.type_name == "Bit";
        if (d.ty.is_none() && !bits) || d.components == 0 {
            continue;
        }
        let count = tuples
            .checked_mul(d.components)
            .ok_or_else(|| err(d.at, format!("DataArray \"{}\": too many values", d.name)))?;
        out.push(DataArray {
            name: d.name.clone(),
            components: d.components,
            values: if bits {
                dec.bits(d, count)?
            } else {
                dec.f64s(d, count)?
            },
        });
    }
    Ok(out)
}

/// A piece's parts, and how many empty cells it had (left out, with their cell data).
fn decode_piece(dec: &Decoder<'_>, piece: &PieceDesc) -> Result<(MeshParts, usize), Error> {
    let coords = piece
        .coords
        .as_ref()
        .ok_or_else(|| err(piece.at, "<Piece> has no <Points> DataArray"))?;
    if coords.components != 3 {
        return Err(err(
            coords.at,
            format!("Points have {} components, expected 3", coords.components),
        )
        .into());
    }
    let points = dec.points(coords, piece.points)?;
    if let Some(extent) = piece.extent {
        return Ok((structured_piece(dec, piece, extent, points)?, 0));
    }

    let types_desc = cell_array(piece, "types")?;
    let offsets_desc = cell_array(piece, "offsets")?;
    let conn_desc = cell_array(piece, "connectivity")?;
    let types_i = dec.i64s(types_desc, piece.cells)?;
    let types: Vec<u8> = types_i
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            u8::try_from(t).map_err(|_| {
                err(
                    types_desc.at,
                    format!("cell {i} has type {t}, not a VTK cell type"),
                )
            })
        })
        .collect::<Result<_, _>>()?;
    let offsets = dec.i64s(offsets_desc, piece.cells)?;
    let conn_len = offsets.last().copied().unwrap_or(0);
    let conn_len = usize::try_from(conn_len)
        .map_err(|_| err(offsets_desc.at, format!("the last cell ends at {conn_len}")))?;
    let converted = dec.cells(conn_desc, conn_len, &offsets, &types, piece.points)?;
    let mut cell_data = data_arrays(dec, &piece.cell_data, piece.cells)?;
    drop_tuples(&mut cell_data, &converted.empty, piece.cells);
    let parts = MeshParts {
        points,
        cells: converted.cells,
        kinds: converted.kinds,
        point_data: data_arrays(dec, &piece.point_data, piece.points)?,
        cell_data,
    };
    Ok((parts, converted.empty.len()))
}

/// A structured grid's piece: the hexahedra of its extent over its points (i fastest, as
/// [`crate::io::structured::hexahedra`] takes them), and its arrays. A piece flat along an
/// axis has no volume cells, and is an error saying so.
fn structured_piece(
    dec: &Decoder<'_>,
    piece: &PieceDesc,
    extent: [i64; 6],
    points: Vec<DVec3>,
) -> Result<MeshParts, Error> {
    let dims = [0, 2, 4].map(|a| (extent[a + 1] - extent[a] + 1) as usize);
    if dims.contains(&1) {
        return Err(err(
            piece.at,
            format!(
                "the piece's Extent {extent:?} is flat along an axis: its cells are not \
                 volumes, and cylvol renders volume cells only"
            ),
        )
        .into());
    }
    let cells = crate::io::structured::hexahedra(dims, &points);
    Ok(MeshParts {
        kinds: vec![crate::mesh::CellKind::Hexahedron; cells.len()],
        cells,
        point_data: data_arrays(dec, &piece.point_data, piece.points)?,
        cell_data: data_arrays(dec, &piece.cell_data, piece.cells)?,
        points,
    })
}

/// Arrays of all pieces joined: those present (same name and components) in every piece.
fn join_arrays(per_piece: Vec<Vec<DataArray>>) -> Vec<DataArray> {
    let mut iter = per_piece.into_iter();
    let Some(mut joined) = iter.next() else {
        return Vec::new();
    };
    for arrays in iter {
        joined.retain_mut(|a| {
            match arrays
                .iter()
                .find(|b| b.name == a.name && b.components == a.components)
            {
                Some(b) => {
                    a.values.extend_from_slice(&b.values);
                    true
                }
                None => false,
            }
        });
    }
    joined
}

/// Joins pieces: points appended, point ids offset, arrays joined by name (those in every
/// piece); `Err` with a message when the points would not fit 32-bit ids.
pub(super) fn join_pieces(pieces: Vec<MeshParts>) -> Result<MeshParts, String> {
    let total: u64 = pieces.iter().map(|p| p.points.len() as u64).sum();
    if total > u32::MAX as u64 + 1 {
        return Err(format!("{total} points in all pieces, more than 2³²"));
    }
    let mut pieces = pieces.into_iter();
    let Some(mut parts) = pieces.next() else {
        return Ok(MeshParts::default());
    };
    let mut point_data = vec![std::mem::take(&mut parts.point_data)];
    let mut cell_data = vec![std::mem::take(&mut parts.cell_data)];
    for d in pieces {
        // Below 2³² + 1 in all (checked above).
        let base = parts.points.len() as u32;
        parts.points.extend_from_slice(&d.points);
        parts
            .cells
            .extend(d.cells.iter().map(|c| c.map(|i| i.wrapping_add(base))));
        parts.kinds.extend_from_slice(&d.kinds);
        point_data.push(d.point_data);
        cell_data.push(d.cell_data);
    }
    parts.point_data = join_arrays(point_data);
    parts.cell_data = join_arrays(cell_data);
    Ok(parts)
}

/// A file's pieces joined, not yet validated, with the scalar the file names as active
/// (`point:NAME` or `cell:NAME`), if any, and what was done beyond reading, for the user.
#[derive(Debug)]
pub(crate) struct FileParts {
    /// The joined pieces, their empty, ghost and blanked cells dropped.
    pub parts: MeshParts,
    /// The active scalar the file names.
    pub active: Option<String>,
    /// Notes: which cells were dropped, how many, and why.
    pub notes: Vec<String>,
}

/// A VTU file's pieces joined, ghost cells dropped, not yet validated, with the scalar the
/// file names as active (`point:NAME` or `cell:NAME`), if any.
pub(super) fn read_parts(bytes: &[u8]) -> Result<FileParts, Error> {
    let parsed = parse_structure(bytes, XmlDataset::UnstructuredGrid)?;
    let dec = decoder_checked(bytes, &parsed)?;
    decode_parts(&dec, &parsed, Blanking::Cells)
}

/// [`read_parts`] of a VTK structured grid (`.vts`): each piece's hexahedra over its extent,
/// the pieces joined (the points on the faces they share are each piece's own), ghost and
/// blanked cells dropped, a hidden point hiding its cells as VTK's structured grids hide
/// them.
pub(crate) fn read_structured_parts(bytes: &[u8]) -> Result<FileParts, Error> {
    let parsed = parse_structure(bytes, XmlDataset::StructuredGrid)?;
    let dec = decoder_checked(bytes, &parsed)?;
    decode_parts(&dec, &parsed, Blanking::CellsAndPoints)
}

/// The decoder of a file read whole, once the XML after its appended data (if any) is
/// checked.
fn decoder_checked<'a>(bytes: &'a [u8], parsed: &Parsed<'a>) -> Result<Decoder<'a>, ReadError> {
    let dec = Decoder {
        bytes,
        layout: parsed.layout,
        appended: parsed.appended,
    };
    match parsed.appended {
        Some(Appended::Raw { start, .. }) => {
            let end = appended_end(&dec, parsed)?;
            check_trailer(bytes, start + end, &parsed.resume)?;
        }
        Some(Appended::Base64 { text, start }) => {
            check_trailer(bytes, start + text.len(), &parsed.resume)?
        }
        None => {}
    }
    Ok(dec)
}

/// The point arrays of a VTK image (`.vti`) of one piece (what VTK's image writer writes):
/// its whole extent, the arrays of the types the reader decodes, and the name of the
/// piece's active point scalars, if it names them.
#[derive(Debug)]
pub(crate) struct ImagePoints {
    pub extent: [i64; 6],
    pub arrays: Vec<DataArray>,
    pub active: Option<String>,
}

/// Reads a `.vti` file's bytes into [`ImagePoints`]; an image of more than one non-empty
/// piece, or whose piece does not cover its whole extent, is an error.
pub(crate) fn read_image_points(bytes: &[u8]) -> Result<ImagePoints, ReadError> {
    let parsed = parse_structure(bytes, XmlDataset::ImageData)?;
    let dec = decoder_checked(bytes, &parsed)?;
    let extent = parsed
        .whole_extent
        .ok_or_else(|| err(0, "no <ImageData> element"))?;
    let pieces: Vec<&PieceDesc> = parsed.pieces.iter().filter(|p| p.points > 0).collect();
    let piece = match pieces.as_slice() {
        [one] => *one,
        [] => return Err(err(0, "the image has no <Piece>")),
        [_, second, ..] => {
            return Err(err(
                second.at,
                format!(
                    "the image has {} pieces; only images of one piece are read",
                    pieces.len()
                ),
            ))
        }
    };
    if piece.extent != Some(extent) {
        return Err(err(
            piece.at,
            "the <Piece> Extent is not the <ImageData> WholeExtent",
        ));
    }
    Ok(ImagePoints {
        extent,
        arrays: data_arrays(&dec, &piece.point_data, piece.points)?,
        active: piece.active_point.clone(),
    })
}

/// How much of a file [`read_file_parts`] reads first to find the start of raw appended
/// data (VTK's writers put a few kilobytes of XML before it).
#[cfg(unix)]
pub(super) const HEAD_BYTES: usize = 1 << 16;

/// [`read_parts`] of a file, reading raw appended data an array at a time from where the
/// file has it instead of the whole file first: the first `head` bytes are parsed, and if
/// the XML before a raw `<AppendedData>` lies within them, each array's bytes are read at
/// their offset (arrays no piece uses are not read at all) and the trailer after the data
/// from the end of the file. `Ok(None)` when the file is not such a file (no raw appended
/// data, XML longer than `head`, or a file of `head` bytes or fewer) or could not be read:
/// the caller reads it whole, which gives the same result or error.
#[cfg(unix)]
pub(super) fn read_file_parts(
    file: &std::fs::File,
    head: usize,
) -> Result<Option<FileParts>, Error> {
    let Some(len) = file
        .metadata()
        .ok()
        .filter(|m| m.is_file())
        .and_then(|m| usize::try_from(m.len()).ok())
        .filter(|&len| len > head)
    else {
        return Ok(None);
    };
    let mut bytes = vec![0; head];
    if crate::io::read_exact_at(file, &mut bytes, 0).is_err() {
        return Ok(None);
    }
    let Ok(mut parsed) = parse_structure(&bytes, XmlDataset::UnstructuredGrid) else {
        return Ok(None);
    };
    let Some(Appended::Raw { start, .. }) = parsed.appended else {
        return Ok(None);
    };
    parsed.appended = Some(Appended::Raw {
        data: RawData::File {
            file,
            len: len - start,
        },
        start,
    });
    let dec = Decoder {
        bytes: &bytes,
        layout: parsed.layout,
        appended: parsed.appended,
    };
    let trailer_at = start + appended_end(&dec, &parsed)?;
    let mut trailer = vec![0; len - trailer_at];
    if crate::io::read_exact_at(file, &mut trailer, trailer_at as u64).is_err() {
        return Ok(None);
    }
    check_trailer(&trailer, 0, &parsed.resume).map_err(|mut e| {
        e.offset += trailer_at as u64;
        e
    })?;
    decode_parts(&dec, &parsed, Blanking::Cells).map(Some)
}

/// Where (within the raw appended block) the last of the file's appended arrays ends.
fn appended_end(dec: &Decoder<'_>, parsed: &Parsed<'_>) -> Result<usize, ReadError> {
    let mut end = 0;
    let mut arrays = parsed.appended_arrays.clone();
    arrays.sort_unstable();
    arrays.dedup_by_key(|a| a.0);
    for &(offset, at) in &arrays {
        end = end.max(dec.appended_end(offset, at)?);
    }
    Ok(end)
}

/// Decodes the non-empty pieces, joins them and drops ghost cells (and what `blanking` hides).
fn decode_parts(
    dec: &Decoder<'_>,
    parsed: &Parsed<'_>,
    blanking: Blanking,
) -> Result<FileParts, Error> {
    // Empty pieces (parallel writers leave them) may lack arrays altogether: skip them.
    let pieces: Vec<&PieceDesc> = parsed
        .pieces
        .iter()
        .filter(|p| p.points > 0 || p.cells > 0)
        .collect();
    let mut decoded = Vec::with_capacity(pieces.len());
    let mut empty_cells = 0;
    for piece in &pieces {
        let (parts, empty) = decode_piece(dec, piece)?;
        decoded.push(parts);
        empty_cells += empty;
    }
    let mut parts = if decoded.len() == 1 {
        // One piece (the usual case): move, do not copy.
        decoded.pop().unwrap_or_default()
    } else {
        let at = pieces.first().map_or(0, |p| p.at);
        join_pieces(decoded).map_err(|m| err(at, m))?
    };
    let dropped = drop_ghost_cells(&mut parts, blanking);
    let active = pieces.first().and_then(|first| {
        first
            .active_point
            .as_ref()
            .map(|n| format!("point:{n}"))
            .or_else(|| first.active_cell.as_ref().map(|n| format!("cell:{n}")))
    });
    let notes = empty::note(empty_cells)
        .into_iter()
        .chain(dropped.notes())
        .collect();
    Ok(FileParts {
        parts,
        active,
        notes,
    })
}

/// A validated mesh from joined parts, with `active` (`point:NAME` or `cell:NAME`) as its
/// active scalar where that array survived the join.
pub(crate) fn mesh_with_active(parts: MeshParts, active: Option<&str>) -> Result<Mesh, Error> {
    let mut mesh = Mesh::from_parts(parts)?;
    if let Some(name) = active {
        let _ = mesh.set_active_scalar(name);
    }
    Ok(mesh)
}

/// Reads a VTU file's bytes into a validated mesh.
pub(super) fn read(bytes: &[u8]) -> Result<Mesh, Error> {
    let file = read_parts(bytes)?;
    mesh_with_active(file.parts, file.active.as_deref())
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use crate::datasets::{generate, Dataset};
    use crate::io::vtu::{write_with, ByteOrder, Encoding, HeaderType, VtuOptions};

    /// What a read gave, comparable: the parts or the error's message.
    fn outcome(r: Result<FileParts, Error>) -> Result<String, String> {
        r.map(|p| format!("{p:?}")).map_err(|e| e.to_string())
    }

    /// `read_file_parts` over `bytes` written to a file, with a head of `head` bytes.
    fn from_file(bytes: &[u8], head: usize) -> Option<Result<String, String>> {
        let mut file = tempfile::tempfile().unwrap();
        std::io::Write::write_all(&mut file, bytes).unwrap();
        read_file_parts(&file, head).transpose().map(outcome)
    }

    /// Raw appended files (uncompressed and zlib, both header widths, both byte orders) read
    /// from the file an array at a time give what their bytes give: the same parts, and for
    /// the file cut short anywhere or with bytes of its sizes and data overwritten, the same
    /// error. A head that ends before the appended data starts, or holds the whole file,
    /// leaves the file to be read whole (`None`).
    #[test]
    fn reading_arrays_from_the_file_equals_reading_its_bytes() {
        let mesh = generate(Dataset::PumpInlet, 1000).unwrap();
        for (zlib, header, byte_order) in [
            (None, HeaderType::UInt64, ByteOrder::LittleEndian),
            (None, HeaderType::UInt32, ByteOrder::BigEndian),
            (Some(6), HeaderType::UInt32, ByteOrder::LittleEndian),
            (Some(1), HeaderType::UInt64, ByteOrder::BigEndian),
        ] {
            let options = VtuOptions {
                encoding: Encoding::AppendedRaw,
                zlib,
                header,
                byte_order,
                block_size: 1 << 12,
            };
            let mut bytes = Vec::new();
            write_with(&mesh, &mut bytes, &options).unwrap();
            let what = format!("{options:?}");
            let data = bytes
                .windows(14)
                .position(|w| w == b"<AppendedData ")
                .unwrap();
            let start = data + bytes[data..].iter().position(|&b| b == b'_').unwrap() + 1;
            let whole = outcome(read_parts(&bytes));
            assert!(whole.is_ok(), "{what}");
            for head in [start, start + 1, start + 500, bytes.len() - 1] {
                assert_eq!(
                    from_file(&bytes, head),
                    Some(whole.clone()),
                    "{what} head {head}"
                );
            }
            for head in [10, start - 1, bytes.len(), bytes.len() + 9] {
                assert_eq!(from_file(&bytes, head), None, "{what} head {head}");
            }
            let mut errors = 0;
            let trailer = [bytes.len() - 20, bytes.len() - 8, bytes.len() - 2];
            for cut in (1..40)
                .map(|k| start + (bytes.len() - start) * k / 40)
                .chain(trailer)
            {
                let short = &bytes[..cut];
                let want = outcome(read_parts(short));
                errors += usize::from(want.is_err());
                assert_eq!(from_file(short, start), Some(want), "{what} cut at {cut}");
            }
            assert_eq!(errors, 42, "{what}: every cut is an error");
            let spread = (0..60).map(|k| start + (bytes.len() - start - 9) * k / 60 + k % 9);
            let values = [0u8, 0xff, 0x7f, 3, b'x'].into_iter().cycle();
            for (at, value) in spread.chain(trailer).zip(values) {
                let mut bad = bytes.clone();
                bad[at] = value;
                let want = outcome(read_parts(&bad));
                assert_eq!(
                    from_file(&bad, start),
                    Some(want),
                    "{what} byte {at} = {value}"
                );
            }
        }
    }
}
