//! Decoding of VTU data arrays: ascii text, base64, raw bytes, blocks compressed by any of
//! VTK's three compressors (zlib, LZ4, LZMA), 32- and 64-bit size headers, either byte order,
//! and the ten numeric element types.
//!
//! Every size a file states is checked against the bytes really present before anything is
//! allocated from it; compressed blocks are decompressed into buffers of their stated size and
//! must fill them exactly.

use std::borrow::Cow;

use flate2::{Decompress, FlushDecompress, Status};
use rayon::prelude::*;

use crate::error::ReadError;
use crate::io::elements::ScalarType;

use super::FORMAT;

/// How each block of a binary array is compressed: the `compressor` attribute of the
/// `VTKFile` element, one of the `vtkDataCompressor`s VTK's XML writers offer (ParaView's
/// "Compressor Type").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Compressor {
    /// `vtkZLibDataCompressor`: a zlib stream a block.
    Zlib,
    /// `vtkLZ4DataCompressor`: an LZ4 block (the raw block format, no frame) a block.
    Lz4,
    /// `vtkLZMADataCompressor`: an `.xz` stream a block.
    Lzma,
}

impl Compressor {
    /// The compressor a `compressor` attribute names (`None` for names VTK does not write).
    pub fn parse(name: &str) -> Option<Compressor> {
        Some(match name {
            "vtkZLibDataCompressor" => Compressor::Zlib,
            "vtkLZ4DataCompressor" => Compressor::Lz4,
            "vtkLZMADataCompressor" => Compressor::Lzma,
            _ => return None,
        })
    }

    /// Its name in error messages.
    fn name(self) -> &'static str {
        match self {
            Compressor::Zlib => "zlib",
            Compressor::Lz4 => "LZ4",
            Compressor::Lzma => "LZMA",
        }
    }

    /// Most bytes one compressed byte can expand to, with some margin: checked against a
    /// block's stated sizes before its buffer is allocated. Deflate's limit is about 1032;
    /// an LZ4 match grows by 255 bytes a length byte; `.xz` streams of zeros reach about
    /// 6,800 (64 MiB from 9.9 kB).
    fn max_ratio(self) -> u64 {
        match self {
            Compressor::Zlib => 1100,
            Compressor::Lz4 => 260,
            Compressor::Lzma => 10_000,
        }
    }
}

/// How binary data is laid out: from the `VTKFile` attributes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Layout {
    /// `byte_order="BigEndian"`.
    pub big_endian: bool,
    /// `header_type="UInt64"`.
    pub header64: bool,
    /// The `compressor` attribute (`None` where there is none).
    pub compressor: Option<Compressor>,
}

impl Layout {
    fn header_size(self) -> usize {
        if self.header64 {
            8
        } else {
            4
        }
    }

    fn word(self, b: &[u8]) -> u64 {
        match (self.header64, self.big_endian) {
            (true, false) => u64::from_le_bytes(b[..8].try_into().unwrap_or([0; 8])),
            (true, true) => u64::from_be_bytes(b[..8].try_into().unwrap_or([0; 8])),
            (false, false) => u32::from_le_bytes(b[..4].try_into().unwrap_or([0; 4])) as u64,
            (false, true) => u32::from_be_bytes(b[..4].try_into().unwrap_or([0; 4])) as u64,
        }
    }
}

/// A stream of bytes: raw appended data or decoded base64.
pub(super) trait Source<'a> {
    /// The next `n` bytes, or an error if fewer remain.
    fn take(&mut self, n: usize) -> Result<Cow<'a, [u8]>, ReadError>;
    /// An upper bound on the bytes that remain.
    fn remaining_max(&self) -> usize;
    /// The file offset of the next byte (of its encoding, for base64).
    fn offset(&self) -> u64;
    /// Moves past the next `n` bytes, or an error if fewer remain.
    fn skip(&mut self, n: usize) -> Result<(), ReadError> {
        self.take(n).map(|_| ())
    }
    /// An error at the current position.
    fn error(&self, message: String) -> ReadError {
        ReadError::new(FORMAT, self.offset(), message)
    }
}

/// Raw bytes of the appended-data block.
pub(super) struct RawSource<'a> {
    data: &'a [u8],
    pos: usize,
    base: u64,
}

impl<'a> RawSource<'a> {
    /// A source over `data`, which starts at file offset `base`, reading from `pos`.
    pub fn new(data: &'a [u8], base: usize, pos: usize) -> RawSource<'a> {
        RawSource {
            data,
            pos,
            base: base as u64,
        }
    }
}

/// Where `n` bytes from `pos` end in data of `len` bytes, or the error of data ending first.
fn end_of(source: &dyn Source<'_>, pos: usize, n: usize, len: usize) -> Result<usize, ReadError> {
    pos.checked_add(n).filter(|&e| e <= len).ok_or_else(|| {
        source.error(format!(
            "data ends early: {n} bytes needed, {} remain",
            len.saturating_sub(pos)
        ))
    })
}

impl<'a> Source<'a> for RawSource<'a> {
    fn take(&mut self, n: usize) -> Result<Cow<'a, [u8]>, ReadError> {
        let end = end_of(self, self.pos, n, self.data.len())?;
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(Cow::Borrowed(s))
    }

    fn remaining_max(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    fn offset(&self) -> u64 {
        self.base + self.pos as u64
    }
}

/// Raw appended data left in its file: each `take` reads its bytes at their position (in
/// parallel chunks), so a file is never read whole, and `skip` reads nothing.
#[cfg(unix)]
pub(super) struct FileSource<'a> {
    file: &'a std::fs::File,
    /// Bytes of appended data, from `base` to the end of the file.
    len: usize,
    pos: usize,
    base: u64,
}

#[cfg(unix)]
impl<'a> FileSource<'a> {
    /// A source over the `len` bytes of `file` from offset `base`, reading from `pos`.
    pub fn new(file: &'a std::fs::File, base: usize, len: usize, pos: usize) -> FileSource<'a> {
        FileSource {
            file,
            len,
            pos,
            base: base as u64,
        }
    }
}

#[cfg(unix)]
impl<'a> Source<'a> for FileSource<'a> {
    fn take(&mut self, n: usize) -> Result<Cow<'a, [u8]>, ReadError> {
        let end = end_of(self, self.pos, n, self.len)?;
        let mut bytes = vec![0; n];
        crate::io::read_exact_at(self.file, &mut bytes, self.offset())
            .map_err(|e| self.error(format!("could not read {n} bytes of the file: {e}")))?;
        self.pos = end;
        Ok(Cow::Owned(bytes))
    }

    fn skip(&mut self, n: usize) -> Result<(), ReadError> {
        self.pos = end_of(self, self.pos, n, self.len)?;
        Ok(())
    }

    fn remaining_max(&self) -> usize {
        self.len.saturating_sub(self.pos)
    }

    fn offset(&self) -> u64 {
        self.base + self.pos as u64
    }
}

const INVALID: u8 = 0xff;
const PAD: u8 = 0xfe;
const SPACE: u8 = 0xfd;

const fn base64_table() -> [u8; 256] {
    let mut t = [INVALID; 256];
    let alphabet = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut i = 0;
    while i < 64 {
        t[alphabet[i] as usize] = i as u8;
        i += 1;
    }
    t[b'=' as usize] = PAD;
    t[b' ' as usize] = SPACE;
    t[b'\t' as usize] = SPACE;
    t[b'\n' as usize] = SPACE;
    t[b'\r' as usize] = SPACE;
    t
}

static BASE64: [u8; 256] = base64_table();

/// Base64 text decoded on demand. Several independently padded runs one after another (as VTK
/// writes a compressed array's header and its blocks) decode to their bytes one after another;
/// white space is ignored.
pub(super) struct Base64Source<'a> {
    text: &'a [u8],
    pos: usize,
    base: u64,
    pending: [u8; 3],
    pending_start: usize,
    pending_end: usize,
}

impl<'a> Base64Source<'a> {
    /// A decoder over `text`, which starts at file offset `base`, decoding from `pos`.
    pub fn new(text: &'a [u8], base: usize, pos: usize) -> Base64Source<'a> {
        Base64Source {
            text,
            pos,
            base: base as u64,
            pending: [0; 3],
            pending_start: 0,
            pending_end: 0,
        }
    }

    /// The next four significant characters' values (slow path: white space, padding).
    fn group(&mut self) -> Result<Option<([u8; 4], usize)>, ReadError> {
        let mut vals = [0u8; 4];
        let mut n = 0;
        let group_at = self.pos;
        while n < 4 {
            let Some(&c) = self.text.get(self.pos) else {
                if n == 0 {
                    return Ok(None);
                }
                return Err(ReadError::new(
                    FORMAT,
                    self.base + group_at as u64,
                    "base64 data ends in the middle of a 4-character group",
                ));
            };
            let v = BASE64[c as usize];
            self.pos += 1;
            match v {
                SPACE => continue,
                INVALID => {
                    return Err(ReadError::new(
                        FORMAT,
                        self.base + self.pos as u64 - 1,
                        format!("invalid base64 character {:?}", c as char),
                    ))
                }
                _ => {
                    vals[n] = v;
                    n += 1;
                }
            }
        }
        let bytes = match (vals[2] == PAD, vals[3] == PAD) {
            _ if vals[0] == PAD || vals[1] == PAD => 0,
            (true, true) => 1,
            (false, true) => 2,
            (false, false) => 3,
            (true, false) => 0,
        };
        if bytes == 0 {
            return Err(ReadError::new(
                FORMAT,
                self.base + group_at as u64,
                "misplaced '=' in base64 data",
            ));
        }
        Ok(Some((vals, bytes)))
    }
}

fn decode_group(v: [u8; 4]) -> [u8; 3] {
    let v = v.map(|x| if x >= 64 { 0 } else { x });
    [
        (v[0] << 2) | (v[1] >> 4),
        (v[1] << 4) | (v[2] >> 2),
        (v[2] << 6) | v[3],
    ]
}

impl<'a> Source<'a> for Base64Source<'a> {
    fn take(&mut self, n: usize) -> Result<Cow<'a, [u8]>, ReadError> {
        if n > self.remaining_max() {
            return Err(self.error(format!(
                "base64 data ends early: {n} bytes needed, at most {} remain",
                self.remaining_max()
            )));
        }
        let mut out = Vec::with_capacity(n);
        let from_pending = (self.pending_end - self.pending_start).min(n);
        out.extend_from_slice(&self.pending[self.pending_start..self.pending_start + from_pending]);
        self.pending_start += from_pending;
        while out.len() < n {
            // Fast path: four alphabet characters in a row.
            if let Some(chunk) = self.text.get(self.pos..self.pos + 4) {
                let v = [
                    BASE64[chunk[0] as usize],
                    BASE64[chunk[1] as usize],
                    BASE64[chunk[2] as usize],
                    BASE64[chunk[3] as usize],
                ];
                if v.iter().all(|&x| x < 64) && n - out.len() >= 3 {
                    out.extend_from_slice(&decode_group(v));
                    self.pos += 4;
                    continue;
                }
            }
            let Some((v, count)) = self.group()? else {
                return Err(self.error(format!(
                    "base64 data ends early: {n} bytes needed, {} found",
                    out.len()
                )));
            };
            let bytes = decode_group(v);
            let want = (n - out.len()).min(count);
            out.extend_from_slice(&bytes[..want]);
            self.pending = bytes;
            self.pending_start = want;
            self.pending_end = count;
        }
        Ok(Cow::Owned(out))
    }

    fn remaining_max(&self) -> usize {
        (self.text.len().saturating_sub(self.pos)) / 4 * 3 + (self.pending_end - self.pending_start)
    }

    fn offset(&self) -> u64 {
        self.base + self.pos as u64
    }
}

fn read_word<'a>(src: &mut dyn Source<'a>, layout: Layout) -> Result<u64, ReadError> {
    let b = src.take(layout.header_size())?;
    Ok(layout.word(&b))
}

/// Reads one binary array's bytes (header included) and returns its `expected` bytes of
/// element data, decompressed. `what` names the array in errors.
pub(super) fn read_binary<'a>(
    src: &mut dyn Source<'a>,
    layout: Layout,
    expected: u64,
    what: &str,
) -> Result<Cow<'a, [u8]>, ReadError> {
    let at = src.offset();
    let first = read_word(src, layout)?;
    let Some(compressor) = layout.compressor else {
        if first != expected {
            return Err(ReadError::new(
                FORMAT,
                at,
                format!("{what}: header says {first} bytes, expected {expected}"),
            ));
        }
        let n = usize::try_from(first).map_err(|_| {
            ReadError::new(FORMAT, at, format!("{what}: {first} bytes is too many"))
        })?;
        return src.take(n);
    };
    let blocks = read_block_header(src, layout, compressor, first, what, at)?;
    if blocks.total != expected {
        return Err(ReadError::new(
            FORMAT,
            at,
            format!(
                "{what}: compressed blocks hold {} bytes, expected {expected}",
                blocks.total
            ),
        ));
    }
    let data_at = src.offset();
    let compressed = src.take(blocks.compressed_total)?;
    decompress_blocks(compressor, &compressed, &blocks, data_at, what).map(Cow::Owned)
}

/// Skips one binary array (header included) without decoding it; returns nothing but moves
/// the source past its data.
pub(super) fn skip_binary<'a>(
    src: &mut dyn Source<'a>,
    layout: Layout,
    what: &str,
) -> Result<(), ReadError> {
    let at = src.offset();
    let first = read_word(src, layout)?;
    let n = if let Some(compressor) = layout.compressor {
        read_block_header(src, layout, compressor, first, what, at)?.compressed_total
    } else {
        usize::try_from(first)
            .map_err(|_| ReadError::new(FORMAT, at, format!("{what}: {first} bytes is too many")))?
    };
    if n > src.remaining_max() {
        return Err(src.error(format!(
            "{what}: data ends early: {n} bytes needed, {} remain",
            src.remaining_max()
        )));
    }
    src.skip(n)
}

struct Blocks {
    /// Uncompressed size of each block.
    sizes: Vec<usize>,
    /// Compressed size of each block.
    csizes: Vec<usize>,
    total: u64,
    compressed_total: usize,
}

fn read_block_header<'a>(
    src: &mut dyn Source<'a>,
    layout: Layout,
    compressor: Compressor,
    nblocks: u64,
    what: &str,
    at: u64,
) -> Result<Blocks, ReadError> {
    let hs = layout.header_size() as u64;
    let bad = |m: String| ReadError::new(FORMAT, at, format!("{what}: {m}"));
    let block = read_word(src, layout)?;
    let last = read_word(src, layout)?;
    let words_bytes = nblocks
        .checked_mul(hs)
        .filter(|&b| b <= src.remaining_max() as u64)
        .ok_or_else(|| {
            bad(format!(
                "{nblocks} compressed blocks claimed, data ends first"
            ))
        })?;
    let words = src.take(words_bytes as usize)?;
    if nblocks == 0 {
        return Ok(Blocks {
            sizes: Vec::new(),
            csizes: Vec::new(),
            total: 0,
            compressed_total: 0,
        });
    }
    if block == 0 || last > block {
        return Err(bad(format!(
            "bad compression header: block size {block}, last block size {last}"
        )));
    }
    let last = if last == 0 { block } else { last };
    let total = (nblocks - 1)
        .checked_mul(block)
        .and_then(|t| t.checked_add(last))
        .ok_or_else(|| bad("compressed size overflows".into()))?;
    let mut sizes = Vec::with_capacity(nblocks as usize);
    let mut csizes = Vec::with_capacity(nblocks as usize);
    let mut compressed_total: u64 = 0;
    for (i, w) in words.chunks_exact(hs as usize).enumerate() {
        let csize = layout.word(w);
        let usize_ = if i as u64 == nblocks - 1 { last } else { block };
        if usize_
            > csize
                .saturating_mul(compressor.max_ratio())
                .saturating_add(64)
        {
            return Err(bad(format!(
                "block {i} claims {usize_} bytes from {csize} compressed bytes"
            )));
        }
        compressed_total = compressed_total
            .checked_add(csize)
            .ok_or_else(|| bad("compressed size overflows".into()))?;
        sizes.push(usize_ as usize);
        csizes.push(csize as usize);
    }
    if compressed_total > src.remaining_max() as u64 {
        return Err(bad(format!(
            "blocks need {compressed_total} compressed bytes, at most {} remain",
            src.remaining_max()
        )));
    }
    Ok(Blocks {
        sizes,
        csizes,
        total,
        compressed_total: compressed_total as usize,
    })
}

fn decompress_blocks(
    compressor: Compressor,
    compressed: &[u8],
    blocks: &Blocks,
    data_at: u64,
    what: &str,
) -> Result<Vec<u8>, ReadError> {
    let total = usize::try_from(blocks.total)
        .map_err(|_| ReadError::new(FORMAT, data_at, format!("{what}: too large")))?;
    let mut out = vec![0u8; total];
    // Pair each output chunk with its compressed input and file offset.
    let mut jobs = Vec::with_capacity(blocks.sizes.len());
    let mut rest: &mut [u8] = &mut out;
    let mut cpos = 0usize;
    for (i, (&size, &csize)) in blocks.sizes.iter().zip(&blocks.csizes).enumerate() {
        let (chunk, tail) = rest.split_at_mut(size.min(rest.len()));
        rest = tail;
        let input = compressed.get(cpos..cpos + csize).unwrap_or(&[]);
        jobs.push((i, chunk, input, data_at + cpos as u64));
        cpos += csize;
    }
    // The first bad block is reported, whichever thread finds a bad block first.
    let first_error = jobs
        .into_par_iter()
        .find_map_first(|(i, chunk, input, at)| {
            let bad = |m: &str| {
                let name = compressor.name();
                ReadError::new(FORMAT, at, format!("{what}: {name} block {i}: {m}"))
            };
            match compressor {
                Compressor::Zlib => inflate(input, chunk, bad),
                Compressor::Lz4 => lz4_block(input, chunk, bad),
                Compressor::Lzma => xz_stream(input, chunk, bad),
            }
            .err()
        });
    match first_error {
        Some(e) => Err(e),
        None => Ok(out),
    }
}

/// Decompresses one zlib stream into `out`, which it must fill exactly; `bad` makes the
/// error for a message.
fn inflate(input: &[u8], out: &mut [u8], bad: impl Fn(&str) -> ReadError) -> Result<(), ReadError> {
    let mut z = Decompress::new(true);
    let mut consumed = 0usize;
    let mut produced = 0usize;
    loop {
        let status = z
            .decompress(
                &input[consumed..],
                &mut out[produced..],
                FlushDecompress::None,
            )
            .map_err(|e| bad(&format!("corrupt data ({e})")))?;
        let (ci, po) = (z.total_in() as usize, z.total_out() as usize);
        let progressed = ci != consumed || po != produced;
        consumed = ci;
        produced = po;
        match status {
            Status::StreamEnd => {
                return if produced == out.len() {
                    Ok(())
                } else {
                    Err(bad(&format!(
                        "decompresses to {produced} bytes, the header says {}",
                        out.len()
                    )))
                }
            }
            _ if produced == out.len() => {
                // Full output but no stream end: either more data than stated, or a missing end.
                let mut probe = [0u8; 1];
                let status = z
                    .decompress(&input[consumed..], &mut probe, FlushDecompress::None)
                    .map_err(|e| bad(&format!("corrupt data ({e})")))?;
                return match status {
                    Status::StreamEnd if z.total_out() as usize == out.len() => Ok(()),
                    _ if z.total_out() as usize > out.len() => Err(bad(&format!(
                        "decompresses to more than the {} bytes the header says",
                        out.len()
                    ))),
                    _ => Err(bad("the compressed stream is truncated")),
                };
            }
            _ if !progressed || consumed >= input.len() => {
                return Err(bad("the compressed stream is truncated"));
            }
            _ => {}
        }
    }
}

/// Decompresses one LZ4 block into `out`, which it must fill exactly.
fn lz4_block(
    input: &[u8],
    out: &mut [u8],
    bad: impl Fn(&str) -> ReadError,
) -> Result<(), ReadError> {
    use lz4_flex::block::DecompressError;
    match lz4_flex::block::decompress_into(input, out) {
        Ok(n) if n == out.len() => Ok(()),
        Ok(n) => Err(bad(&format!(
            "decompresses to {n} bytes, the header says {}",
            out.len()
        ))),
        Err(DecompressError::OutputTooSmall { .. }) => Err(bad(&format!(
            "decompresses to more than the {} bytes the header says",
            out.len()
        ))),
        Err(e) => Err(bad(&format!("corrupt data ({e})"))),
    }
}

/// Decompresses one `.xz` stream into `out`, which it must fill exactly.
fn xz_stream(
    input: &[u8],
    out: &mut [u8],
    bad: impl Fn(&str) -> ReadError,
) -> Result<(), ReadError> {
    /// Writes into a fixed buffer; more than it holds is an error, remembered.
    struct Fill<'o> {
        out: &'o mut [u8],
        len: usize,
        overflow: bool,
    }
    impl std::io::Write for Fill<'_> {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            let room = self.out.len() - self.len;
            if buf.len() > room {
                self.overflow = true;
                return Err(std::io::ErrorKind::WriteZero.into());
            }
            self.out[self.len..self.len + buf.len()].copy_from_slice(buf);
            self.len += buf.len();
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let expected = out.len();
    let mut fill = Fill {
        out,
        len: 0,
        overflow: false,
    };
    let result = lzma_rs::xz_decompress(&mut &input[..], &mut fill);
    if fill.overflow {
        return Err(bad(&format!(
            "decompresses to more than the {expected} bytes the header says"
        )));
    }
    match result {
        Err(e) => Err(bad(&format!("corrupt data ({e})"))),
        Ok(()) if fill.len != expected => Err(bad(&format!(
            "decompresses to {} bytes, the header says {expected}",
            fill.len
        ))),
        Ok(()) => Ok(()),
    }
}

/// Parses `count` whitespace-separated numbers from ascii text as `f64`.
pub(super) fn ascii_f64(
    text: &[u8],
    base: usize,
    count: usize,
    what: &str,
) -> Result<Vec<f64>, ReadError> {
    parse_ascii(text, base, count, what, |s| s.parse::<f64>().ok())
}

/// Parses `count` whitespace-separated integers from ascii text as `i64`.
pub(super) fn ascii_i64(
    text: &[u8],
    base: usize,
    count: usize,
    ty: ScalarType,
    what: &str,
) -> Result<Vec<i64>, ReadError> {
    if ty.is_float() {
        return Err(ReadError::new(
            FORMAT,
            base as u64,
            format!("{what} must have an integer type"),
        ));
    }
    parse_ascii(text, base, count, what, |s| {
        s.parse::<i64>()
            .ok()
            .or_else(|| s.parse::<u64>().ok().map(|_| i64::MAX))
    })
}

fn parse_ascii<T>(
    text: &[u8],
    base: usize,
    count: usize,
    what: &str,
    parse: impl Fn(&str) -> Option<T>,
) -> Result<Vec<T>, ReadError> {
    let mut out = Vec::with_capacity(count.min(text.len() / 2 + 1));
    let mut pos = 0;
    while pos < text.len() {
        while text.get(pos).is_some_and(|b| b.is_ascii_whitespace()) {
            pos += 1;
        }
        if pos >= text.len() {
            break;
        }
        let start = pos;
        while text.get(pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            pos += 1;
        }
        let token = &text[start..pos];
        let value = std::str::from_utf8(token)
            .ok()
            .and_then(&parse)
            .ok_or_else(|| {
                ReadError::new(
                    FORMAT,
                    (base + start) as u64,
                    format!(
                        "{what}: bad number {:?}",
                        String::from_utf8_lossy(&token[..token.len().min(40)])
                    ),
                )
            })?;
        if out.len() == count {
            return Err(ReadError::new(
                FORMAT,
                (base + start) as u64,
                format!("{what}: more than the expected {count} values"),
            ));
        }
        out.push(value);
    }
    if out.len() != count {
        return Err(ReadError::new(
            FORMAT,
            (base + text.len()) as u64,
            format!("{what}: {} values, expected {count}", out.len()),
        ));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    fn b64(bytes: &[u8]) -> String {
        base64::engine::general_purpose::STANDARD.encode(bytes)
    }

    #[test]
    fn base64_runs_concatenate_and_ignore_space() {
        let a = b64(b"ab");
        let b = b64(b"cdefg");
        let text = format!(" {a}\n {b} ");
        let mut src = Base64Source::new(text.as_bytes(), 0, 0);
        assert_eq!(&*src.take(3).unwrap(), b"abc");
        assert_eq!(&*src.take(4).unwrap(), b"defg");
        assert!(src.take(1).is_err());
    }

    #[test]
    fn bad_base64_is_an_error() {
        for bad in ["ab$d", "a=bc", "abc", "=abc"] {
            let mut src = Base64Source::new(bad.as_bytes(), 0, 0);
            assert!(src.take(1).is_err(), "{bad}");
        }
    }

    /// One block compressed as `compressor` writes it (the LZMA one as a plain `.xz` stream:
    /// VTK's are checked against files it wrote, in `tests/vtu.rs`).
    fn compress(compressor: Compressor, block: &[u8]) -> Vec<u8> {
        use std::io::Write;
        match compressor {
            Compressor::Zlib => {
                let mut e =
                    flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
                e.write_all(block).unwrap();
                e.finish().unwrap()
            }
            Compressor::Lz4 => lz4_flex::block::compress(block),
            Compressor::Lzma => {
                let mut out = Vec::new();
                lzma_rs::xz_compress(&mut &block[..], &mut out).unwrap();
                out
            }
        }
    }

    #[test]
    fn compressed_blocks_decode_and_lies_are_caught() {
        // Repetitive enough that every compressor shortens it.
        let data: Vec<u8> = (0..100u8).map(|i| i % 7).collect();
        for compressor in [Compressor::Zlib, Compressor::Lz4, Compressor::Lzma] {
            let blocks: Vec<Vec<u8>> = data.chunks(64).map(|c| compress(compressor, c)).collect();
            let layout = Layout {
                big_endian: false,
                header64: false,
                compressor: Some(compressor),
            };
            let file = |header: [u32; 3], blocks: &[Vec<u8>]| {
                let mut f = Vec::new();
                for w in header {
                    f.extend_from_slice(&w.to_le_bytes());
                }
                for b in blocks {
                    f.extend_from_slice(&(b.len() as u32).to_le_bytes());
                }
                for b in blocks {
                    f.extend_from_slice(b);
                }
                f
            };
            let read = |f: &[u8], expected: u64| {
                read_binary(&mut RawSource::new(f, 0, 0), layout, expected, "a")
                    .map(|bytes| bytes.into_owned())
            };
            let name = compressor.name();
            let good = file([2, 64, 36], &blocks);
            assert_eq!(&*read(&good, 100).unwrap(), &data[..], "{name}");
            // A stated last-block size that disagrees with the stream.
            let e = read(&file([2, 64, 30], &blocks), 94).unwrap_err();
            assert!(e.message.contains("more than"), "{name}: {e}");
            assert!(e.message.contains(&format!("{name} block 1")), "{e}");
            let e = read(&file([2, 64, 40], &blocks), 104).unwrap_err();
            assert!(e.message.contains("decompresses to 36"), "{name}: {e}");
            // Corrupt compressed bytes: an error or (where the corruption still decodes, as
            // a raw LZ4 block may) other bytes, never a panic.
            for (k, flip) in [(0usize, 0x55u8), (3, 0x80), (7, 0xff)] {
                let mut bad = blocks.clone();
                let b = &mut bad[0];
                let at = k.min(b.len() - 1);
                b[at] ^= flip;
                let _ = read(&file([2, 64, 36], &bad), 100);
            }
            // One block's bytes cut short.
            let mut short = blocks.clone();
            let half = short[1].len() / 2;
            short[1].truncate(half);
            assert!(read(&file([2, 64, 36], &short), 100).is_err(), "{name}");
            // Too many blocks claimed.
            let mut huge = good.clone();
            huge[..4].copy_from_slice(&u32::MAX.to_le_bytes());
            assert!(read(&huge, 100).is_err(), "{name}");
            // A block claiming more than its compressor can expand it to.
            let ratio = compressor.max_ratio() as u32;
            let e = read(
                &file([1, 10 * ratio, 10 * ratio], &[vec![0; 9]]),
                10 * ratio as u64,
            );
            assert!(e.unwrap_err().message.contains("claims"), "{name}");
        }
    }
    #[test]
    fn ascii_counts_are_checked() {
        assert_eq!(
            ascii_f64(b" 1 2.5\n-3e2 ", 0, 3, "a").unwrap(),
            vec![1.0, 2.5, -300.0]
        );
        assert!(ascii_f64(b"1 2", 0, 3, "a").is_err());
        assert!(ascii_f64(b"1 2 3 4", 0, 3, "a").is_err());
        assert!(ascii_f64(b"1 x 3", 0, 3, "a").is_err());
        assert!(ascii_i64(b"1 2.5", 0, 2, ScalarType::I32, "a").is_err());
    }
}
