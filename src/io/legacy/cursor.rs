//! A cursor over a legacy VTK file: whitespace-separated ASCII tokens, whole lines, and raw
//! binary blocks, with the byte offset (and, for text, the line number) of every error.
//!
//! The file is either all in memory (tokens, lines and blocks are then slices of it, never
//! allocated) or read from disk as it is parsed ([`Cursor::over_file`]): text through a small
//! window, each binary block with positioned reads of exactly its bytes, so that a large
//! binary file is never held whole.

use std::borrow::Cow;

use crate::error::ReadError;

/// The format name errors carry.
pub(super) const FORMAT: &str = "legacy VTK";

/// A whitespace-separated word of the file and where it starts.
#[derive(Clone, Debug)]
pub(super) struct Token<'a> {
    /// The word's bytes.
    pub text: Cow<'a, [u8]>,
    /// Byte offset of its first byte.
    pub offset: usize,
}

impl Token<'_> {
    /// Whether the word is `keyword`, ignoring ASCII case (VTK lower-cases keywords).
    pub fn is(&self, keyword: &str) -> bool {
        self.text.eq_ignore_ascii_case(keyword.as_bytes())
    }

    /// The word for messages: lossy UTF-8, shortened to 40 characters.
    pub fn show(&self) -> String {
        show(&self.text)
    }
}

/// Bytes for messages: lossy UTF-8 with control characters escaped, shortened to 40 characters.
pub(super) fn show(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out: String = text.chars().take(40).flat_map(char::escape_debug).collect();
    if text.chars().count() > 40 {
        out.push('…');
    }
    out
}

/// C's `isspace` on ASCII bytes, as `operator>>` uses it.
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

/// Why a binary block could not be taken.
#[derive(Debug)]
pub(super) enum Shortfall {
    /// The file ends first; it held this many bytes of the block.
    Truncated(usize),
    /// Reading the file failed.
    Io(std::io::Error),
}

/// Reading position in a legacy VTK file.
pub(super) struct Cursor<'a> {
    data: Data<'a>,
    pos: usize,
    /// Where the first binary block starts: line numbers past it are not meaningful.
    binary_from: Option<usize>,
}

/// Where the file's bytes come from.
enum Data<'a> {
    /// The whole file, in memory.
    Bytes(&'a [u8]),
    /// The file on disk, read as it is parsed.
    #[cfg(unix)]
    File(FileWindow<'a>),
}

/// Bytes of a file on disk from offset `start`, read `chunk` at a time where text is scanned.
#[cfg(unix)]
struct FileWindow<'a> {
    file: &'a std::fs::File,
    /// The file's length when it was opened: what the cursor reads up to.
    len: usize,
    start: usize,
    window: Vec<u8>,
    chunk: usize,
}

#[cfg(unix)]
impl FileWindow<'_> {
    /// The bytes from `pos` that are in memory, read from the file if none are; empty at the
    /// end of the file (or where it cannot be read: the file changed, which the next block's
    /// read or the missing text then reports).
    fn view(&mut self, pos: usize) -> &[u8] {
        use std::os::unix::fs::FileExt;
        let end = self.start + self.window.len();
        if pos < self.start || pos >= end {
            let n = self.chunk.min(self.len.saturating_sub(pos));
            self.window.resize(n, 0);
            let got = self.file.read_at(&mut self.window, pos as u64).unwrap_or(0);
            self.window.truncate(got);
            self.start = pos;
        }
        &self.window[pos - self.start..]
    }

    /// The `n` bytes from `pos` (which the file's length holds).
    fn block(&mut self, pos: usize, n: usize) -> std::io::Result<Vec<u8>> {
        let end = self.start + self.window.len();
        if pos >= self.start && pos + n <= end {
            return Ok(self.window[pos - self.start..pos - self.start + n].to_vec());
        }
        let mut block = vec![0; n];
        crate::io::read_exact_at(self.file, &mut block, pos as u64)?;
        Ok(block)
    }

    /// The newlines in the file's first `end` bytes (`None` if they cannot be read).
    fn newlines_before(&self, end: usize) -> Option<usize> {
        use std::os::unix::fs::FileExt;
        let mut buf = vec![0; self.chunk.max(1 << 16)];
        let (mut at, mut count) = (0, 0);
        while at < end {
            let n = buf.len().min(end - at);
            self.file.read_exact_at(&mut buf[..n], at as u64).ok()?;
            count += buf[..n].iter().filter(|&&b| b == b'\n').count();
            at += n;
        }
        Some(count)
    }
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Cursor<'a> {
        Cursor {
            data: Data::Bytes(bytes),
            pos: 0,
            binary_from: None,
        }
    }

    /// A cursor at the start of a file of `len` bytes on disk, scanning text `chunk` bytes at
    /// a time (at least one).
    #[cfg(unix)]
    pub fn over_file(file: &'a std::fs::File, len: usize, chunk: usize) -> Cursor<'a> {
        Cursor {
            data: Data::File(FileWindow {
                file,
                len,
                start: 0,
                window: Vec::new(),
                chunk: chunk.max(1),
            }),
            pos: 0,
            binary_from: None,
        }
    }

    /// The current byte offset.
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// The length of the file.
    pub fn len(&self) -> usize {
        match &self.data {
            Data::Bytes(b) => b.len(),
            #[cfg(unix)]
            Data::File(w) => w.len,
        }
    }

    /// Bytes left after the current position.
    pub fn remaining(&self) -> usize {
        self.len().saturating_sub(self.pos)
    }

    /// An error at `offset`, with its line number where lines are meaningful (text before the
    /// first binary block).
    pub fn error(&self, offset: usize, message: impl Into<String>) -> ReadError {
        let error = ReadError::new(FORMAT, offset as u64, message);
        if self.binary_from.is_some_and(|b| offset > b) {
            return error;
        }
        let end = offset.min(self.len());
        let newlines = match &self.data {
            Data::Bytes(b) => Some(b[..end].iter().filter(|&&b| b == b'\n').count()),
            #[cfg(unix)]
            Data::File(w) => w.newlines_before(end),
        };
        match newlines {
            Some(n) => error.at_line(1 + n),
            None => error,
        }
    }

    /// The bytes from the current position that are in memory (empty at the end).
    fn rest(&mut self) -> &[u8] {
        match &mut self.data {
            Data::Bytes(b) => b.get(self.pos..).unwrap_or_default(),
            #[cfg(unix)]
            Data::File(w) => w.view(self.pos),
        }
    }

    /// Skips whitespace (newlines included).
    pub fn skip_space(&mut self) {
        loop {
            let rest = self.rest();
            let (step, done) = match rest.iter().position(|&b| !is_space(b)) {
                Some(k) => (k, true),
                None => (rest.len(), rest.is_empty()),
            };
            self.pos += step;
            if done {
                return;
            }
        }
    }

    /// The bytes from the current position up to the first one `stop` holds for (or the end
    /// of the file), moving past them.
    fn take_until(&mut self, stop: impl Fn(u8) -> bool) -> Cow<'a, [u8]> {
        if let Data::Bytes(bytes) = self.data {
            let rest = bytes.get(self.pos..).unwrap_or_default();
            let len = rest.iter().position(|&b| stop(b)).unwrap_or(rest.len());
            self.pos += len;
            return Cow::Borrowed(&rest[..len]);
        }
        let mut out = Vec::new();
        loop {
            let rest = self.rest();
            let (step, done) = match rest.iter().position(|&b| stop(b)) {
                Some(k) => (k, true),
                None => (rest.len(), rest.is_empty()),
            };
            out.extend_from_slice(&rest[..step]);
            self.pos += step;
            if done {
                return Cow::Owned(out);
            }
        }
    }

    /// The next word, after any whitespace; `None` at the end of the file.
    pub fn token(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        let offset = self.pos;
        let text = self.take_until(is_space);
        (!text.is_empty()).then_some(Token { text, offset })
    }

    /// The next word without moving.
    pub fn peek_token(&mut self) -> Option<Token<'a>> {
        let pos = self.pos;
        let token = self.token();
        self.pos = pos;
        token
    }

    /// The rest of the current line (without its `\n` and a trailing `\r`), moving past the
    /// newline; `None` at the end of the file.
    pub fn line(&mut self) -> Option<Cow<'a, [u8]>> {
        if self.rest().is_empty() {
            return None;
        }
        let line = self.take_until(|b| b == b'\n');
        if !self.rest().is_empty() {
            self.pos += 1;
        }
        Some(match line {
            Cow::Borrowed(l) => Cow::Borrowed(l.strip_suffix(b"\r").unwrap_or(l)),
            Cow::Owned(mut l) => {
                if l.last() == Some(&b'\r') {
                    l.pop();
                }
                Cow::Owned(l)
            }
        })
    }

    /// Moves past the rest of the current line, where binary data starts (VTK's reader
    /// discards the rest of the keyword line before binary data).
    pub fn start_binary(&mut self) {
        let _ = self.line();
        self.binary_from.get_or_insert(self.pos);
    }

    /// Takes `n` raw bytes after the rest of the current line ([`Cursor::start_binary`]).
    pub fn binary(&mut self, n: usize) -> Result<Cow<'a, [u8]>, Shortfall> {
        self.start_binary();
        self.bytes(n)
    }

    /// Takes the next byte as it is; `None` at the end of the file.
    pub fn byte(&mut self) -> Option<u8> {
        let b = *self.rest().first()?;
        self.pos += 1;
        Some(b)
    }

    /// Moves past `n` bytes without reading them, or to the end of the file if it holds fewer
    /// (then `false`).
    pub fn skip(&mut self, n: u64) -> bool {
        let remaining = self.remaining();
        match usize::try_from(n) {
            Ok(n) if n <= remaining => {
                self.pos += n;
                true
            }
            _ => {
                self.pos = self.len();
                false
            }
        }
    }

    /// Takes `n` raw bytes from the current position.
    fn bytes(&mut self, n: usize) -> Result<Cow<'a, [u8]>, Shortfall> {
        let available = self.remaining();
        if n > available {
            self.pos = self.len();
            return Err(Shortfall::Truncated(available));
        }
        let pos = self.pos;
        self.pos += n;
        match &mut self.data {
            Data::Bytes(b) => Ok(Cow::Borrowed(&b[pos..pos + n])),
            #[cfg(unix)]
            Data::File(w) => w.block(pos, n).map(Cow::Owned).map_err(Shortfall::Io),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// Runs `check` on a cursor over `bytes` in memory and, on Unix, over the same bytes in a
    /// file, scanned 1, 2, 3, 5 and 4,096 bytes at a time.
    fn both_ways(bytes: &[u8], check: impl Fn(&mut Cursor)) {
        check(&mut Cursor::new(bytes));
        #[cfg(unix)]
        {
            let mut file = tempfile::tempfile().unwrap();
            file.write_all(bytes).unwrap();
            for chunk in [1, 2, 3, 5, 4096] {
                check(&mut Cursor::over_file(&file, bytes.len(), chunk));
            }
        }
    }

    #[test]
    fn tokens_lines_and_binary() {
        both_ways(b"  POINTS 2 float\r\nab\ncd\r\n\nNEXT", |c| {
            let t = c.token().unwrap();
            assert!(t.is("points") && t.offset == 2);
            assert_eq!(*c.peek_token().unwrap().text, *b"2");
            assert_eq!(*c.token().unwrap().text, *b"2");
            assert_eq!(*c.token().unwrap().text, *b"float");
            assert_eq!(*c.binary(3).unwrap(), *b"ab\n");
            assert_eq!(*c.line().unwrap(), *b"cd");
            assert_eq!(*c.line().unwrap(), *b"");
            assert_eq!(c.pos(), 26);
            assert_eq!(*c.token().unwrap().text, *b"NEXT");
            assert!(c.token().is_none());
            assert!(c.line().is_none());
            assert_eq!(c.remaining(), 0);
        });
    }

    /// A block beyond what the text window holds is read from the file whole, and text after
    /// it is scanned again from its end.
    #[test]
    fn long_blocks_and_tokens() {
        let mut file = b"W ".to_vec();
        file.extend((0..300).map(|i| b'a' + (i % 26) as u8));
        file.extend(b"\nX\n");
        file.extend((0..1000u32).map(|i| (i * 7) as u8));
        file.extend(b"END");
        both_ways(&file, |c| {
            assert_eq!(*c.token().unwrap().text, file[..1]);
            assert_eq!(*c.token().unwrap().text, file[2..302]);
            assert_eq!(*c.token().unwrap().text, *b"X");
            assert_eq!(*c.binary(1000).unwrap(), file[305..1305]);
            assert_eq!(*c.token().unwrap().text, *b"END");
        });
    }

    /// Bytes one at a time and skips, across the text window's edges and to the end.
    #[test]
    fn bytes_and_skips() {
        both_ways(b"S 1\n\xc2ab\xc0\x01Z", |c| {
            assert_eq!(*c.token().unwrap().text, *b"S");
            assert_eq!(*c.token().unwrap().text, *b"1");
            c.start_binary();
            assert_eq!(c.byte(), Some(0xc2));
            assert!(c.skip(2));
            assert_eq!((c.byte(), c.byte()), (Some(0xc0), Some(1)));
            assert_eq!(c.pos(), 9);
            assert!(!c.skip(2));
            assert_eq!((c.pos(), c.byte()), (10, None));
            assert!(c.skip(0) && !c.skip(u64::MAX));
        });
    }

    #[test]
    fn binary_past_the_end_says_how_much_there_was() {
        both_ways(b"X\n0123", |c| {
            c.token();
            assert!(matches!(c.binary(9), Err(Shortfall::Truncated(4))));
            assert!(c.token().is_none());
        });
    }

    #[test]
    fn errors_have_lines_only_before_binary_data() {
        both_ways(b"a\nb\nc\n\n\n\n", |c| {
            assert_eq!(c.error(4, "x").line, Some(3));
            c.token();
            c.binary(2).unwrap();
            assert_eq!(c.error(5, "x").line, None);
            assert_eq!(c.error(1, "x").line, Some(1));
        });
    }
}
