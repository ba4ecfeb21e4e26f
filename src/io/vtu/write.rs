//! The VTU writer: an `UnstructuredGrid` with Float64 points, Int64 connectivity and offsets,
//! UInt8 types and Float64 point and cell arrays, in any of VTK's encodings (ascii, inline
//! base64, appended raw or base64), optionally zlib-compressed in blocks as
//! `vtkZLibDataCompressor` does, with 32- or 64-bit size headers in either byte order.

use std::io::{self, BufWriter, Write};

use base64::engine::general_purpose::STANDARD;
use base64::write::EncoderWriter;
use flate2::write::ZlibEncoder;
use rayon::prelude::*;

use super::xml::escape;
use crate::mesh::Association;
use crate::Mesh;

/// How array data is stored in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// Numbers as text inside each `DataArray` (`format="ascii"`; never compressed).
    Ascii,
    /// Base64 inside each `DataArray` (`format="binary"`).
    Base64,
    /// Raw bytes in one `<AppendedData encoding="raw">` block at the end (`format="appended"`).
    AppendedRaw,
    /// Base64 in one `<AppendedData encoding="base64">` block at the end.
    AppendedBase64,
}

/// Width of the size words before each binary array (`header_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HeaderType {
    /// 32-bit sizes (VTK's default before 9 and the only choice of file version 0.1). Arrays
    /// over 4 GiB must then be compressed.
    UInt32,
    /// 64-bit sizes.
    UInt64,
}

/// Byte order of binary data (`byte_order`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ByteOrder {
    /// Least significant byte first (every machine VTK runs on today).
    LittleEndian,
    /// Most significant byte first.
    BigEndian,
}

/// How [`super::write_with`] writes a file. [`VtuOptions::default`] is what
/// [`super::write`] uses: appended raw data, uncompressed, 64-bit headers, little-endian.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VtuOptions {
    /// Where and how array data is stored.
    pub encoding: Encoding,
    /// zlib compression level (0–9) for binary encodings, `None` for none. Ignored for
    /// [`Encoding::Ascii`].
    pub zlib: Option<u32>,
    /// Width of the size words.
    pub header: HeaderType,
    /// Byte order of binary data.
    pub byte_order: ByteOrder,
    /// Uncompressed bytes per compressed block (VTK uses 32 KiB).
    pub block_size: usize,
}

impl Default for VtuOptions {
    fn default() -> VtuOptions {
        VtuOptions {
            encoding: Encoding::AppendedRaw,
            zlib: None,
            header: HeaderType::UInt64,
            byte_order: ByteOrder::LittleEndian,
            block_size: 1 << 15,
        }
    }
}

/// One number of an array, as written.
#[derive(Clone, Copy)]
enum Num {
    F(f64),
    I(i64),
    U8(u8),
}

/// What an array holds; the mesh is borrowed, nothing is copied up front.
enum Payload<'m> {
    Values(&'m [f64]),
    Points(&'m [glam::DVec3]),
    Connectivity(&'m Mesh),
    Offsets(&'m Mesh),
    Types(&'m Mesh),
}

impl Payload<'_> {
    fn type_name(&self) -> &'static str {
        match self {
            Payload::Values(_) | Payload::Points(_) => "Float64",
            Payload::Connectivity(_) | Payload::Offsets(_) => "Int64",
            Payload::Types(_) => "UInt8",
        }
    }

    fn elem_size(&self) -> usize {
        match self {
            Payload::Types(_) => 1,
            _ => 8,
        }
    }

    fn count(&self) -> usize {
        match self {
            Payload::Values(v) => v.len(),
            Payload::Points(p) => 3 * p.len(),
            Payload::Connectivity(m) => m.kinds().iter().map(|k| k.vertex_count()).sum(),
            Payload::Offsets(m) | Payload::Types(m) => m.cell_count(),
        }
    }

    fn bytes(&self) -> u64 {
        self.count() as u64 * self.elem_size() as u64
    }

    fn numbers(&self) -> Box<dyn Iterator<Item = Num> + '_> {
        match self {
            Payload::Values(v) => Box::new(v.iter().map(|&x| Num::F(x))),
            Payload::Points(p) => Box::new(p.iter().flat_map(|p| [p.x, p.y, p.z]).map(Num::F)),
            Payload::Connectivity(m) => Box::new(m.vtk_connectivity().map(|i| Num::I(i.into()))),
            Payload::Offsets(m) => Box::new(m.vtk_cell_ends().map(|end| Num::I(end as i64))),
            Payload::Types(m) => Box::new(m.vtk_cell_types().map(Num::U8)),
        }
    }
}

/// Appends the next (up to) `max` numbers' bytes; returns whether any were appended.
fn fill(it: &mut dyn Iterator<Item = Num>, max: usize, big: bool, out: &mut Vec<u8>) -> bool {
    let before = out.len();
    for n in it.take(max) {
        match (n, big) {
            (Num::F(x), false) => out.extend_from_slice(&x.to_le_bytes()),
            (Num::F(x), true) => out.extend_from_slice(&x.to_be_bytes()),
            (Num::I(x), false) => out.extend_from_slice(&x.to_le_bytes()),
            (Num::I(x), true) => out.extend_from_slice(&x.to_be_bytes()),
            (Num::U8(x), _) => out.push(x),
        }
    }
    out.len() > before
}

const BATCH: usize = 1 << 14;

struct Spec<'m> {
    name: String,
    components: usize,
    payload: Payload<'m>,
}

/// An array compressed into blocks.
struct Compressed {
    /// Size words: block count, block size, last block size, compressed sizes.
    header: Vec<u8>,
    blocks: Vec<Vec<u8>>,
}

impl Compressed {
    fn data_len(&self) -> u64 {
        self.blocks.iter().map(|b| b.len() as u64).sum()
    }
}

fn invalid(m: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, m)
}

fn word(v: u64, opts: &VtuOptions, out: &mut Vec<u8>) -> io::Result<()> {
    let big = opts.byte_order == ByteOrder::BigEndian;
    match opts.header {
        HeaderType::UInt64 => out.extend_from_slice(&if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }),
        HeaderType::UInt32 => {
            let v = u32::try_from(v).map_err(|_| {
                invalid(format!(
                    "{v} does not fit a UInt32 VTU header (use HeaderType::UInt64 or compression)"
                ))
            })?;
            out.extend_from_slice(&if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    }
    Ok(())
}

fn header_size(opts: &VtuOptions) -> u64 {
    match opts.header {
        HeaderType::UInt32 => 4,
        HeaderType::UInt64 => 8,
    }
}

fn zlib_block(data: &[u8], level: u32) -> io::Result<Vec<u8>> {
    let mut e = ZlibEncoder::new(
        Vec::with_capacity(data.len() / 2 + 64),
        flate2::Compression::new(level.min(9)),
    );
    e.write_all(data)?;
    e.finish()
}

fn compress(payload: &Payload<'_>, level: u32, opts: &VtuOptions) -> io::Result<Compressed> {
    let bs = opts.block_size;
    let big = opts.byte_order == ByteOrder::BigEndian;
    let chunk = bs.saturating_mul(4 * rayon::current_num_threads().max(1));
    let mut it = payload.numbers();
    let mut buf = Vec::new();
    let mut blocks = Vec::new();
    loop {
        let more = fill(&mut *it, BATCH, big, &mut buf);
        if buf.len() >= chunk || !more {
            let take = if more { buf.len() / bs * bs } else { buf.len() };
            let done: Vec<Vec<u8>> = buf[..take]
                .par_chunks(bs)
                .map(|c| zlib_block(c, level))
                .collect::<io::Result<_>>()?;
            blocks.extend(done);
            buf.drain(..take);
        }
        if !more {
            break;
        }
    }
    let total = payload.bytes();
    let mut header = Vec::new();
    word(blocks.len() as u64, opts, &mut header)?;
    word(bs as u64, opts, &mut header)?;
    word(total % bs as u64, opts, &mut header)?;
    for b in &blocks {
        word(b.len() as u64, opts, &mut header)?;
    }
    Ok(Compressed { header, blocks })
}

fn base64_len(n: u64) -> u64 {
    n.div_ceil(3) * 4
}

/// Bytes an array takes in the appended block.
fn appended_size(payload: &Payload<'_>, compressed: Option<&Compressed>, opts: &VtuOptions) -> u64 {
    let raw = opts.encoding == Encoding::AppendedRaw;
    match compressed {
        None => {
            let n = header_size(opts) + payload.bytes();
            if raw {
                n
            } else {
                base64_len(n)
            }
        }
        Some(c) => {
            let (h, d) = (c.header.len() as u64, c.data_len());
            if raw {
                h + d
            } else {
                base64_len(h) + base64_len(d)
            }
        }
    }
}

/// Writes an array's binary form (header and data), raw or as base64 runs, as VTK does: one
/// run for an uncompressed array, separate runs for a compressed array's header and blocks.
fn write_binary(
    w: &mut dyn Write,
    payload: &Payload<'_>,
    compressed: Option<&Compressed>,
    base64: bool,
    opts: &VtuOptions,
) -> io::Result<()> {
    let big = opts.byte_order == ByteOrder::BigEndian;
    match compressed {
        None => {
            let mut header = Vec::new();
            word(payload.bytes(), opts, &mut header)?;
            let mut it = payload.numbers();
            let mut buf = Vec::with_capacity(BATCH * 8);
            if base64 {
                let mut enc = EncoderWriter::new(&mut *w, &STANDARD);
                enc.write_all(&header)?;
                while fill(&mut *it, BATCH, big, &mut buf) {
                    enc.write_all(&buf)?;
                    buf.clear();
                }
                enc.finish()?;
            } else {
                w.write_all(&header)?;
                while fill(&mut *it, BATCH, big, &mut buf) {
                    w.write_all(&buf)?;
                    buf.clear();
                }
            }
        }
        Some(c) => {
            if base64 {
                {
                    let mut enc = EncoderWriter::new(&mut *w, &STANDARD);
                    enc.write_all(&c.header)?;
                    enc.finish()?;
                }
                let mut enc = EncoderWriter::new(&mut *w, &STANDARD);
                for b in &c.blocks {
                    enc.write_all(b)?;
                }
                enc.finish()?;
            } else {
                w.write_all(&c.header)?;
                for b in &c.blocks {
                    w.write_all(b)?;
                }
            }
        }
    }
    Ok(())
}

fn fmt_f64(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

fn write_ascii(w: &mut dyn Write, payload: &Payload<'_>, indent: &str) -> io::Result<()> {
    for (i, n) in payload.numbers().enumerate() {
        if i % 6 == 0 {
            if i > 0 {
                w.write_all(b"\n")?;
            }
            w.write_all(indent.as_bytes())?;
        } else {
            w.write_all(b" ")?;
        }
        match n {
            Num::F(x) => w.write_all(fmt_f64(x).as_bytes())?,
            Num::I(x) => write!(w, "{x}")?,
            Num::U8(x) => write!(w, "{x}")?,
        }
    }
    w.write_all(b"\n")
}

/// The arrays of the file, by section, in file order.
fn data_specs(arrays: &[crate::DataArray]) -> Vec<Spec<'_>> {
    arrays
        .iter()
        .map(|a| Spec {
            name: a.name.clone(),
            components: a.components,
            payload: Payload::Values(&a.values),
        })
        .collect()
}

fn specs(mesh: &Mesh) -> [(&'static str, Vec<Spec<'_>>); 4] {
    [
        ("PointData", data_specs(mesh.point_data())),
        ("CellData", data_specs(mesh.cell_data())),
        (
            "Points",
            vec![Spec {
                name: "Points".into(),
                components: 3,
                payload: Payload::Points(mesh.points()),
            }],
        ),
        (
            "Cells",
            vec![
                Spec {
                    name: "connectivity".into(),
                    components: 1,
                    payload: Payload::Connectivity(mesh),
                },
                Spec {
                    name: "offsets".into(),
                    components: 1,
                    payload: Payload::Offsets(mesh),
                },
                Spec {
                    name: "types".into(),
                    components: 1,
                    payload: Payload::Types(mesh),
                },
            ],
        ),
    ]
}

/// Writes the mesh as a VTU file with the given options.
pub(super) fn write_with(mesh: &Mesh, out: &mut dyn Write, opts: &VtuOptions) -> io::Result<()> {
    if opts.block_size == 0 {
        return Err(invalid("VTU block size must be positive".into()));
    }
    let mut w = BufWriter::with_capacity(1 << 16, out);
    let sections = specs(mesh);
    let level = match opts.encoding {
        Encoding::Ascii => None,
        _ => opts.zlib,
    };
    let appended = matches!(
        opts.encoding,
        Encoding::AppendedRaw | Encoding::AppendedBase64
    );

    // Compress appended arrays up front: their sizes decide the offsets in the XML.
    let mut pre: Vec<Option<Compressed>> = Vec::new();
    if appended {
        for (_, specs) in &sections {
            for s in specs {
                pre.push(match level {
                    Some(l) => Some(compress(&s.payload, l, opts)?),
                    None => None,
                });
            }
        }
    }

    let byte_order = match opts.byte_order {
        ByteOrder::LittleEndian => "LittleEndian",
        ByteOrder::BigEndian => "BigEndian",
    };
    let header_type = match opts.header {
        HeaderType::UInt32 => "UInt32",
        HeaderType::UInt64 => "UInt64",
    };
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    write!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"{byte_order}\" header_type=\"{header_type}\""
    )?;
    if level.is_some() {
        write!(w, " compressor=\"vtkZLibDataCompressor\"")?;
    }
    writeln!(w, ">")?;
    writeln!(w, "  <UnstructuredGrid>")?;
    writeln!(
        w,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.point_count(),
        mesh.cell_count()
    )?;
    let active = mesh.active_scalar().map(|a| {
        (
            a.association,
            mesh.arrays(a.association)[a.array].name.clone(),
        )
    });
    let format = match opts.encoding {
        Encoding::Ascii => "ascii",
        Encoding::Base64 => "binary",
        _ => "appended",
    };
    let mut offset = 0u64;
    let mut index = 0;
    for (section, specs) in &sections {
        write!(w, "      <{section}")?;
        let assoc = match *section {
            "PointData" => Some(Association::Point),
            "CellData" => Some(Association::Cell),
            _ => None,
        };
        if let (Some(assoc), Some((a, name))) = (assoc, &active) {
            if assoc == *a {
                write!(w, " Scalars=\"{}\"", escape(name))?;
            }
        }
        writeln!(w, ">")?;
        for s in specs {
            write!(
                w,
                "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"{format}\"",
                s.payload.type_name(),
                escape(&s.name),
                s.components
            )?;
            if appended {
                let size = appended_size(&s.payload, pre[index].as_ref(), opts);
                writeln!(w, " offset=\"{offset}\"/>")?;
                offset += size;
                index += 1;
                continue;
            }
            writeln!(w, ">")?;
            match opts.encoding {
                Encoding::Ascii => write_ascii(&mut w, &s.payload, "          ")?,
                _ => {
                    let c = match level {
                        Some(l) => Some(compress(&s.payload, l, opts)?),
                        None => None,
                    };
                    w.write_all(b"          ")?;
                    write_binary(&mut w, &s.payload, c.as_ref(), true, opts)?;
                    w.write_all(b"\n")?;
                }
            }
            writeln!(w, "        </DataArray>")?;
        }
        writeln!(w, "      </{section}>")?;
    }
    writeln!(w, "    </Piece>")?;
    writeln!(w, "  </UnstructuredGrid>")?;
    if appended {
        let raw = opts.encoding == Encoding::AppendedRaw;
        writeln!(
            w,
            "  <AppendedData encoding=\"{}\">",
            if raw { "raw" } else { "base64" }
        )?;
        w.write_all(b"   _")?;
        let mut index = 0;
        for (_, specs) in &sections {
            for s in specs {
                write_binary(&mut w, &s.payload, pre[index].as_ref(), !raw, opts)?;
                index += 1;
            }
        }
        writeln!(w, "\n  </AppendedData>")?;
    }
    writeln!(w, "</VTKFile>")?;
    w.flush()
}
