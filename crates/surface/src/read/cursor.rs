//! A byte cursor shared by every reader: whitespace-separated tokens for
//! the ascii formats, little-endian scalars for the binary ones. Errors
//! carry the position; the line number is only counted when an error is
//! made, so the happy path pays nothing for it.

use super::{Loc, ReadError};

pub(crate) struct Cur<'a> {
    pub name: &'a str,
    pub b: &'a [u8],
    pub pos: usize,
    /// Start of the last token, for error positions.
    pub tok: usize,
    /// Comment character (to end of line), if the format has one.
    comment: Option<u8>,
}

pub(crate) type Res<T> = Result<T, ReadError>;

impl<'a> Cur<'a> {
    pub fn new(name: &'a str, b: &'a [u8], comment: Option<u8>) -> Self {
        Cur {
            name,
            b,
            pos: 0,
            tok: 0,
            comment,
        }
    }

    pub fn remaining(&self) -> usize {
        self.b.len() - self.pos
    }

    pub fn at_end(&self) -> bool {
        self.pos >= self.b.len()
    }

    /// 1-based line number of byte `pos`.
    pub fn line_of(&self, pos: usize) -> usize {
        let pos = pos.min(self.b.len());
        1 + self.b[..pos].iter().filter(|&&c| c == b'\n').count()
    }

    /// Error on the line holding byte `pos`.
    pub fn err_line(&self, pos: usize, what: impl Into<String>) -> ReadError {
        ReadError::Bad {
            file: self.name.to_string(),
            at: Loc::Line(self.line_of(pos)),
            what: what.into(),
        }
    }

    /// Error on the line of the last token.
    pub fn err(&self, what: impl Into<String>) -> ReadError {
        self.err_line(self.tok, what)
    }

    /// Error at byte offset `pos` (binary data).
    pub fn err_byte(&self, pos: usize, what: impl Into<String>) -> ReadError {
        ReadError::Bad {
            file: self.name.to_string(),
            at: Loc::Byte(pos),
            what: what.into(),
        }
    }

    /// Skips whitespace and comments.
    pub fn skip_ws(&mut self) {
        while self.pos < self.b.len() {
            let c = self.b[self.pos];
            if c.is_ascii_whitespace() {
                self.pos += 1;
            } else if Some(c) == self.comment {
                self.skip_line();
            } else {
                break;
            }
        }
    }

    /// Moves past the next newline (or to the end).
    pub fn skip_line(&mut self) {
        match self.b[self.pos..].iter().position(|&c| c == b'\n') {
            Some(i) => self.pos += i + 1,
            None => self.pos = self.b.len(),
        }
    }

    /// The rest of the current line without its line ending; moves past it.
    pub fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        self.skip_line();
        let mut l = &self.b[start..self.pos];
        while let [rest @ .., b'\n' | b'\r'] = l {
            l = rest;
        }
        l
    }

    /// Next whitespace-separated token, or None at end of input.
    pub fn token(&mut self) -> Option<&'a [u8]> {
        self.skip_ws();
        if self.at_end() {
            return None;
        }
        let start = self.pos;
        self.tok = start;
        while self.pos < self.b.len() && !self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Some(&self.b[start..self.pos])
    }

    /// Next token; an error naming `what` at end of input.
    pub fn need(&mut self, what: &str) -> Res<&'a [u8]> {
        match self.token() {
            Some(t) => Ok(t),
            None => {
                self.tok = self.b.len();
                Err(self.err(format!("unexpected end of file, expected {what}")))
            }
        }
    }

    pub fn f64(&mut self, what: &str) -> Res<f64> {
        let t = self.need(what)?;
        parse_f64(t).ok_or_else(|| self.err(format!("expected {what}, found '{}'", show(t))))
    }

    /// A finite coordinate.
    pub fn coord(&mut self, what: &str) -> Res<f64> {
        let v = self.f64(what)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(format!("{what} is not finite ({v})")))
        }
    }

    pub fn i64(&mut self, what: &str) -> Res<i64> {
        let t = self.need(what)?;
        parse_i64(t).ok_or_else(|| self.err(format!("expected {what}, found '{}'", show(t))))
    }

    /// A non-negative integer that fits in u64.
    pub fn u64(&mut self, what: &str) -> Res<u64> {
        let v = self.i64(what)?;
        u64::try_from(v).map_err(|_| self.err(format!("{what} is negative ({v})")))
    }

    /// A non-negative integer that fits in u32.
    pub fn u32(&mut self, what: &str) -> Res<u32> {
        let v = self.i64(what)?;
        u32::try_from(v).map_err(|_| self.err(format!("{what} {v} is out of range")))
    }

    /// Takes `n` raw bytes or fails with a truncation error naming `what`.
    pub fn bytes(&mut self, n: usize, what: &str) -> Res<&'a [u8]> {
        if self.remaining() < n {
            return Err(self.err_byte(
                self.pos,
                format!(
                    "file truncated: expected {what} ({n} bytes, {} left)",
                    self.remaining()
                ),
            ));
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    pub fn le_u32(&mut self, what: &str) -> Res<u32> {
        Ok(u32::from_le_bytes(self.bytes(4, what)?.try_into().unwrap()))
    }
    pub fn le_i32(&mut self, what: &str) -> Res<i32> {
        Ok(i32::from_le_bytes(self.bytes(4, what)?.try_into().unwrap()))
    }
    pub fn le_u64(&mut self, what: &str) -> Res<u64> {
        Ok(u64::from_le_bytes(self.bytes(8, what)?.try_into().unwrap()))
    }
    pub fn le_f64(&mut self, what: &str) -> Res<f64> {
        Ok(f64::from_le_bytes(self.bytes(8, what)?.try_into().unwrap()))
    }
}

pub(crate) fn parse_f64(t: &[u8]) -> Option<f64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

pub(crate) fn parse_i64(t: &[u8]) -> Option<i64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// A token for an error message: lossy, at most 40 characters.
pub(crate) fn show(t: &[u8]) -> String {
    let s = String::from_utf8_lossy(&t[..t.len().min(40)]).into_owned();
    if t.len() > 40 {
        s + "..."
    } else {
        s
    }
}

/// Items of at least `min_bytes` each that the rest of the input could
/// hold: caps a reservation so a bogus count cannot allocate unboundedly.
pub(crate) fn cap(count: u64, remaining: usize, min_bytes: usize) -> usize {
    count.min((remaining / min_bytes.max(1)) as u64) as usize
}

/// Splits an ascii line into whitespace-separated tokens.
pub(crate) fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|c| c.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}
