//! A cursor over the bytes of a legacy VTK file: whitespace-separated ASCII tokens (slices of
//! the input, never allocated), whole lines, and raw binary blocks, with the byte offset (and,
//! for text, the line number) of every error.

use crate::error::ReadError;

/// The format name errors carry.
pub(super) const FORMAT: &str = "legacy VTK";

/// A whitespace-separated word of the file and where it starts.
#[derive(Clone, Copy, Debug)]
pub(super) struct Token<'a> {
    /// The word's bytes.
    pub text: &'a [u8],
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
        show(self.text)
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

/// Reading position in a legacy VTK file.
pub(super) struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Where the first binary block starts: line numbers past it are not meaningful.
    binary_from: Option<usize>,
}

impl<'a> Cursor<'a> {
    /// A cursor at the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Cursor<'a> {
        Cursor {
            bytes,
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
        self.bytes.len()
    }

    /// Bytes left after the current position.
    pub fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    /// An error at `offset`, with its line number where lines are meaningful (text before the
    /// first binary block).
    pub fn error(&self, offset: usize, message: impl Into<String>) -> ReadError {
        let error = ReadError::new(FORMAT, offset as u64, message);
        if self.binary_from.is_some_and(|b| offset > b) {
            return error;
        }
        let end = offset.min(self.bytes.len());
        let line = 1 + self.bytes[..end].iter().filter(|&&b| b == b'\n').count();
        error.at_line(line)
    }

    /// Skips whitespace (newlines included).
    pub fn skip_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !is_space(b) {
                break;
            }
            self.pos += 1;
        }
    }

    /// The next word, after any whitespace; `None` at the end of the file.
    pub fn token(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        let start = self.pos;
        let rest = self.bytes.get(start..)?;
        let len = rest.iter().position(|&b| is_space(b)).unwrap_or(rest.len());
        if len == 0 {
            return None;
        }
        self.pos = start + len;
        Some(Token {
            text: &rest[..len],
            offset: start,
        })
    }

    /// The next word without moving.
    pub fn peek_token(&self) -> Option<Token<'a>> {
        let mut probe = Cursor {
            bytes: self.bytes,
            pos: self.pos,
            binary_from: self.binary_from,
        };
        probe.token()
    }

    /// The rest of the current line (without its `\n` and a trailing `\r`), moving past the
    /// newline; `None` at the end of the file.
    pub fn line(&mut self) -> Option<&'a [u8]> {
        let rest = self.bytes.get(self.pos..).filter(|r| !r.is_empty())?;
        let (line, used) = match rest.iter().position(|&b| b == b'\n') {
            Some(i) => (&rest[..i], i + 1),
            None => (rest, rest.len()),
        };
        self.pos += used;
        Some(line.strip_suffix(b"\r").unwrap_or(line))
    }

    /// Takes `n` raw bytes after the rest of the current line (as VTK's reader discards the
    /// rest of the keyword line before binary data). `Err` holds how many bytes there were.
    pub fn binary(&mut self, n: usize) -> Result<&'a [u8], usize> {
        let _ = self.line();
        self.binary_from.get_or_insert(self.pos);
        let available = self.remaining();
        if n > available {
            self.pos = self.bytes.len();
            return Err(available);
        }
        let block = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(block)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_lines_and_binary() {
        let mut c = Cursor::new(b"  POINTS 2 float\r\nab\ncd\n\nNEXT");
        let t = c.token().unwrap();
        assert!(t.is("points") && t.offset == 2);
        assert_eq!(c.peek_token().unwrap().text, b"2");
        assert_eq!(c.token().unwrap().text, b"2");
        assert_eq!(c.token().unwrap().text, b"float");
        assert_eq!(c.binary(3).unwrap(), b"ab\n");
        assert_eq!(c.line().unwrap(), b"cd");
        assert_eq!(c.line().unwrap(), b"");
        assert_eq!(c.token().unwrap().text, b"NEXT");
        assert!(c.token().is_none());
        assert!(c.line().is_none());
    }

    #[test]
    fn binary_past_the_end_says_how_much_there_was() {
        let mut c = Cursor::new(b"X\n0123");
        c.token();
        assert_eq!(c.binary(9), Err(4));
    }

    #[test]
    fn errors_have_lines_only_before_binary_data() {
        let mut c = Cursor::new(b"a\nb\nc\n\n\n\n");
        assert_eq!(c.error(4, "x").line, Some(3));
        c.token();
        c.binary(2).unwrap();
        assert_eq!(c.error(5, "x").line, None);
        assert_eq!(c.error(1, "x").line, Some(1));
    }
}
