//! A small XML tokenizer, just enough for VTK XML files: start, end and empty-element tags with
//! quoted attributes, text, CDATA; declarations, comments and `<!DOCTYPE …>` are skipped.
//!
//! It works on bytes and can be stopped and resumed at any position, which the VTU reader needs:
//! raw appended data after `<AppendedData encoding="raw">` is arbitrary binary, not XML.

use std::borrow::Cow;
use std::ops::Range;

use crate::error::ReadError;

use super::FORMAT;

/// One attribute of a tag, with character and entity references resolved.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Attr<'a> {
    /// The attribute's name.
    pub name: &'a str,
    /// Its value.
    pub value: Cow<'a, str>,
}

/// What the scanner found next.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Event<'a> {
    /// A start tag, or an empty-element tag (`empty`), at byte `offset`; the tag ends just
    /// before byte `end`.
    Start {
        /// The element's name.
        name: &'a str,
        /// Its attributes in file order.
        attrs: Vec<Attr<'a>>,
        /// `<name …/>`.
        empty: bool,
        /// Byte offset of the `<`.
        offset: usize,
        /// Byte offset just past the `>`.
        end: usize,
    },
    /// An end tag at byte `offset`.
    End {
        /// The element's name.
        name: &'a str,
        /// Byte offset of the `<`.
        offset: usize,
    },
    /// Character data (or a CDATA section's content) as a byte range of the input.
    Text(Range<usize>),
    /// The end of the input.
    Eof,
}

/// A resumable tokenizer over a byte slice.
pub(super) struct Scanner<'a> {
    bytes: &'a [u8],
    pos: usize,
}

fn err(offset: usize, message: impl Into<String>) -> ReadError {
    ReadError::new(FORMAT, offset as u64, message)
}

fn find(hay: &[u8], from: usize, needle: &[u8]) -> Option<usize> {
    let tail = hay.get(from..)?;
    if needle.is_empty() || tail.len() < needle.len() {
        return None;
    }
    tail.windows(needle.len())
        .position(|w| w == needle)
        .map(|i| i + from)
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r')
}

fn is_name_end(b: u8) -> bool {
    is_space(b) || matches!(b, b'/' | b'>' | b'=' | b'<' | b'"' | b'\'')
}

/// Whether every byte of `s` is XML white space.
pub(super) fn is_blank(s: &[u8]) -> bool {
    s.iter().all(|&b| is_space(b))
}

/// The elements open at a scanner's position, innermost last, checked as they open and close:
/// tags must nest, the input must not end inside an element, and no text may stand outside
/// the root. Errors are reported as `format`'s.
pub(super) struct OpenElements<'a> {
    names: Vec<&'a str>,
    format: &'static str,
}

impl<'a> OpenElements<'a> {
    /// None open yet.
    pub fn new(format: &'static str) -> OpenElements<'a> {
        OpenElements {
            names: Vec::new(),
            format,
        }
    }

    /// The open elements' names, outermost first.
    pub fn names(&self) -> &[&'a str] {
        &self.names
    }

    /// The innermost open element.
    pub fn innermost(&self) -> Option<&'a str> {
        self.names.last().copied()
    }

    /// A start tag (not an empty-element one) opened `name`.
    pub fn open(&mut self, name: &'a str) {
        self.names.push(name);
    }

    /// An end tag `</name>` at `offset`: it must close the innermost element.
    pub fn close(&mut self, name: &str, offset: usize) -> Result<(), ReadError> {
        let message = match self.names.pop() {
            Some(open) if open == name => return Ok(()),
            Some(open) => format!("</{name}> closes <{open}>"),
            None => format!("</{name}> without <{name}>"),
        };
        Err(ReadError::new(self.format, offset as u64, message))
    }

    /// Text at `range` of `bytes`: outside the root it must be white space.
    pub fn text(&self, bytes: &[u8], range: &Range<usize>) -> Result<(), ReadError> {
        if self.names.is_empty() && !is_blank(&bytes[range.clone()]) {
            return Err(ReadError::new(
                self.format,
                range.start as u64,
                "not a VTK XML file: text outside elements",
            ));
        }
        Ok(())
    }

    /// The end of `bytes`: no element may be open.
    pub fn end(&self, bytes: &[u8]) -> Result<(), ReadError> {
        match self.names.last() {
            Some(open) => Err(ReadError::new(
                self.format,
                bytes.len() as u64,
                format!("the file ends inside <{open}>"),
            )),
            None => Ok(()),
        }
    }
}

/// The value of the attribute `name`, if the tag has it.
pub(super) fn attr<'x>(attrs: &'x [Attr<'_>], name: &str) -> Option<&'x str> {
    attrs
        .iter()
        .find(|a| a.name == name)
        .map(|a| a.value.as_ref())
}

/// Whether a `VTKFile` tag's `type` is `expected`; if not, what it holds, for an error
/// message (`a PolyData dataset`, `no type attribute`).
pub(super) fn check_file_type(attrs: &[Attr<'_>], expected: &str) -> Result<(), String> {
    match attr(attrs, "type").unwrap_or("") {
        ty if ty == expected => Ok(()),
        "" => Err("no type attribute".to_string()),
        ty => Err(format!("a {ty} dataset")),
    }
}

impl<'a> Scanner<'a> {
    /// A scanner starting at byte `pos`.
    pub fn new(bytes: &'a [u8], pos: usize) -> Scanner<'a> {
        Scanner { bytes, pos }
    }

    /// A scanner over a whole document, past its UTF-8 byte-order mark if it has one.
    pub fn document(bytes: &'a [u8]) -> Scanner<'a> {
        let bom = if bytes.starts_with(b"\xEF\xBB\xBF") {
            3
        } else {
            0
        };
        Scanner::new(bytes, bom)
    }

    /// The current position (the first byte not yet consumed).
    pub fn pos(&self) -> usize {
        self.pos
    }

    fn byte(&self, i: usize) -> Option<u8> {
        self.bytes.get(i).copied()
    }

    fn skip_space(&mut self) {
        while self.byte(self.pos).is_some_and(is_space) {
            self.pos += 1;
        }
    }

    fn name(&mut self, what: &str) -> Result<&'a str, ReadError> {
        let start = self.pos;
        while self.byte(self.pos).is_some_and(|b| !is_name_end(b)) {
            self.pos += 1;
        }
        if self.pos == start {
            return Err(err(start, format!("expected {what} name")));
        }
        std::str::from_utf8(&self.bytes[start..self.pos])
            .map_err(|_| err(start, format!("{what} name is not UTF-8")))
    }

    /// The next event.
    pub fn next_event(&mut self) -> Result<Event<'a>, ReadError> {
        loop {
            if let Some(event) = self.next_inner()? {
                return Ok(event);
            }
        }
    }

    /// The next event, or `None` after skipping a declaration or comment.
    fn next_inner(&mut self) -> Result<Option<Event<'a>>, ReadError> {
        let start = self.pos;
        if start >= self.bytes.len() {
            return Ok(Some(Event::Eof));
        }
        if self.bytes[start] != b'<' {
            let end = self.bytes[start..]
                .iter()
                .position(|&b| b == b'<')
                .map_or(self.bytes.len(), |i| i + start);
            self.pos = end;
            return Ok(Some(Event::Text(start..end)));
        }
        let rest = &self.bytes[start..];
        let skip_to = |needle: &[u8], what: &str| {
            find(self.bytes, start + 1, needle)
                .map(|i| i + needle.len())
                .ok_or_else(|| err(start, format!("unterminated {what}")))
        };
        if rest.starts_with(b"<?") {
            self.pos = skip_to(b"?>", "processing instruction")?;
            return Ok(None);
        }
        if rest.starts_with(b"<!--") {
            self.pos = skip_to(b"-->", "comment")?;
            return Ok(None);
        }
        if rest.starts_with(b"<![CDATA[") {
            let end = skip_to(b"]]>", "CDATA section")?;
            self.pos = end;
            return Ok(Some(Event::Text(start + 9..end - 3)));
        }
        if rest.starts_with(b"<!") {
            self.pos = skip_to(b">", "declaration")?;
            return Ok(None);
        }
        if rest.starts_with(b"</") {
            self.pos = start + 2;
            let name = self.name("element")?;
            self.skip_space();
            if self.byte(self.pos) != Some(b'>') {
                return Err(err(self.pos, format!("expected '>' to close </{name}")));
            }
            self.pos += 1;
            return Ok(Some(Event::End {
                name,
                offset: start,
            }));
        }
        self.pos = start + 1;
        let name = self.name("element")?;
        let mut attrs = Vec::new();
        loop {
            let before = self.pos;
            self.skip_space();
            match self.byte(self.pos) {
                None => return Err(err(start, format!("unterminated <{name}> tag"))),
                Some(b'>') => {
                    self.pos += 1;
                    return Ok(Some(Event::Start {
                        name,
                        attrs,
                        empty: false,
                        offset: start,
                        end: self.pos,
                    }));
                }
                Some(b'/') => {
                    if self.byte(self.pos + 1) != Some(b'>') {
                        return Err(err(self.pos, format!("expected '/>' in <{name}> tag")));
                    }
                    self.pos += 2;
                    return Ok(Some(Event::Start {
                        name,
                        attrs,
                        empty: true,
                        offset: start,
                        end: self.pos,
                    }));
                }
                Some(_) => {
                    if self.pos == before {
                        return Err(err(
                            self.pos,
                            format!("expected white space in <{name}> tag"),
                        ));
                    }
                    let attr_at = self.pos;
                    let attr = self.name("attribute")?;
                    self.skip_space();
                    if self.byte(self.pos) != Some(b'=') {
                        return Err(err(attr_at, format!("attribute {attr} has no value")));
                    }
                    self.pos += 1;
                    self.skip_space();
                    let quote = match self.byte(self.pos) {
                        Some(q @ (b'"' | b'\'')) => q,
                        _ => {
                            return Err(err(
                                self.pos,
                                format!("attribute {attr} value is not quoted"),
                            ))
                        }
                    };
                    let value_start = self.pos + 1;
                    let value_end = self.bytes[value_start..]
                        .iter()
                        .position(|&b| b == quote)
                        .map(|i| i + value_start)
                        .ok_or_else(|| err(attr_at, format!("unterminated attribute {attr}")))?;
                    self.pos = value_end + 1;
                    let raw = std::str::from_utf8(&self.bytes[value_start..value_end])
                        .map_err(|_| err(value_start, format!("attribute {attr} is not UTF-8")))?;
                    let value = unescape(raw).ok_or_else(|| {
                        err(
                            value_start,
                            format!("bad character reference in attribute {attr}"),
                        )
                    })?;
                    attrs.push(Attr { name: attr, value });
                }
            }
        }
    }
}

/// Resolves `&lt;` `&gt;` `&amp;` `&quot;` `&apos;` and numeric character references.
pub(super) fn unescape(raw: &str) -> Option<Cow<'_, str>> {
    if !raw.contains('&') {
        return Some(Cow::Borrowed(raw));
    }
    let mut out = String::with_capacity(raw.len());
    let mut rest = raw;
    while let Some(i) = rest.find('&') {
        out.push_str(&rest[..i]);
        let tail = &rest[i + 1..];
        let semi = tail.find(';')?;
        let entity = &tail[..semi];
        let c = match entity {
            "lt" => '<',
            "gt" => '>',
            "amp" => '&',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code = if let Some(hex) = entity
                    .strip_prefix("#x")
                    .or_else(|| entity.strip_prefix("#X"))
                {
                    u32::from_str_radix(hex, 16).ok()?
                } else {
                    entity.strip_prefix('#')?.parse::<u32>().ok()?
                };
                char::from_u32(code)?
            }
        };
        out.push(c);
        rest = &tail[semi + 1..];
    }
    out.push_str(rest);
    Some(Cow::Owned(out))
}

/// Escapes text for use inside a double-quoted attribute value.
pub(crate) fn escape(text: &str) -> Cow<'_, str> {
    if !text.contains(['<', '>', '&', '"', '\'', '\n', '\r', '\t']) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn events(s: &str) -> Vec<Event<'_>> {
        let mut sc = Scanner::new(s.as_bytes(), 0);
        let mut out = Vec::new();
        loop {
            let e = sc.next_event().unwrap();
            if e == Event::Eof {
                return out;
            }
            out.push(e);
        }
    }

    #[test]
    fn tags_attributes_text_and_skipped_parts() {
        let s =
            "<?xml version=\"1.0\"?><!-- c --><A x='1' y = \"a&amp;b\">t<![CDATA[<z>]]><B/></A>";
        let ev = events(s);
        assert_eq!(ev.len(), 5);
        match &ev[0] {
            Event::Start {
                name, attrs, empty, ..
            } => {
                assert_eq!(*name, "A");
                assert!(!empty);
                assert_eq!(attrs[0].value, "1");
                assert_eq!(attrs[1].name, "y");
                assert_eq!(attrs[1].value, "a&b");
            }
            e => panic!("{e:?}"),
        }
        match &ev[1] {
            Event::Text(r) => assert_eq!(&s[r.clone()], "t"),
            e => panic!("{e:?}"),
        }
        match &ev[2] {
            Event::Text(r) => assert_eq!(&s[r.clone()], "<z>"),
            e => panic!("{e:?}"),
        }
        assert!(matches!(
            ev[3],
            Event::Start {
                name: "B",
                empty: true,
                ..
            }
        ));
        assert!(matches!(ev[4], Event::End { name: "A", .. }));
    }

    #[test]
    fn malformed_tags_are_errors() {
        for bad in [
            "<A",
            "<A x=1>",
            "<A x='1>",
            "<A x>",
            "<!-- x",
            "</A",
            "<A x='1'y='2'>",
            "< >",
        ] {
            let mut sc = Scanner::new(bad.as_bytes(), 0);
            assert!(sc.next_event().is_err(), "{bad}");
        }
    }

    #[test]
    fn escape_and_unescape_round_trip() {
        let s = "a<b>&\"c'\td\n";
        assert_eq!(unescape(&escape(s)).unwrap(), s);
        assert_eq!(unescape("&#65;&#x42;").unwrap(), "AB");
        assert!(unescape("&bogus;").is_none());
        assert!(unescape("&#xD800;").is_none());
    }
}
