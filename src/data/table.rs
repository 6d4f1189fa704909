//! The common shape of rshape's CSV inputs (FRF data, std files, envelopes), read with the
//! `csv` crate: one header, then rows with as many fields as the header.  Every error names
//! the file and the 1-based line.
//!
//! What is accepted beyond plain comma-separated lines: `#` comment lines and blank lines
//! (skipped), a UTF-8 byte-order mark, UTF-16 with a byte-order mark (decoded), CRLF or LF
//! line ends, fields in double quotes (`"re_1_1"`), spaces around fields, trailing empty
//! fields beyond the header's width (a trailing comma), and `;` or tab as the separator
//! when the header line has no comma (the decimal point must still be `.`).
//!
//! Two ways to read: [`Table::parse`] splits a whole text, its fields borrowing from it;
//! [`TableReader`] streams rows from any reader with one reused row buffer, for inputs too
//! large to hold (see `consistency::stream`).

use crate::error::{Error, Result};
use std::io::{BufRead, BufReader, Cursor, Read};
use std::path::{Path, PathBuf};

/// A split CSV table: header names and the rows' fields, with their file lines.
pub struct Table<'a> {
    path: &'a Path,
    /// Line of the header.
    pub header_line: usize,
    /// Column names, trimmed.
    pub names: Vec<&'a str>,
    /// `(line, fields)` of each data row, fields trimmed; every row has `names.len()` fields.
    pub rows: Vec<(usize, Vec<&'a str>)>,
}

impl<'a> Table<'a> {
    /// Splits `text`; `expected_header` is quoted in the message for an empty file.
    pub fn parse(text: &'a str, path: &'a Path, expected_header: &str) -> Result<Self> {
        let mut reader = TableReader::new(text.as_bytes(), path, expected_header)?;
        // The csv crate hands out unescaped copies; each is found again in `text` (a
        // quoted field without doubled quotes is a substring of its raw form, and equal
        // bytes are an equal field wherever they are found), so the fields borrow from
        // `text` as before.  The search starts after the previous field: linear overall.
        let mut cursor = 0;
        let mut locate = |field: &str, line: usize| -> Result<&'a str> {
            match text[cursor..].find(field) {
                Some(k) => {
                    let start = cursor + k;
                    cursor = start + field.len();
                    Ok(&text[start..cursor])
                }
                None => Err(Error::Data {
                    path: path.to_path_buf(),
                    line,
                    msg: format!(
                        "field `{field}` contains an escaped quote: fields are column names or numbers, remove the quotes"
                    ),
                }),
            }
        };
        let header_line = reader.header_line;
        let names = (reader.names.iter())
            .map(|n| locate(n, header_line))
            .collect::<Result<Vec<_>>>()?;
        let mut rows = Vec::new();
        while let Some(line) = reader.next_row()? {
            let fields = (reader.fields())
                .map(|f| locate(f, line))
                .collect::<Result<Vec<_>>>()?;
            rows.push((line, fields));
        }
        Ok(Self {
            path,
            header_line,
            names,
            rows,
        })
    }

    /// An error at `line` of this file.
    pub fn err(&self, line: usize, msg: String) -> Error {
        Error::Data {
            path: self.path.to_path_buf(),
            line,
            msg,
        }
    }

    /// Whether the first column is `freq_hz` (true) or `omega_rad_s` (false).
    pub fn first_column_is_hz(&self) -> Result<bool> {
        first_column_is_hz(self.path, self.header_line, &self.names)
    }
}

fn first_column_is_hz<S: AsRef<str>>(path: &Path, line: usize, names: &[S]) -> Result<bool> {
    match names.first().map(AsRef::as_ref) {
        Some("freq_hz") => Ok(true),
        Some("omega_rad_s") => Ok(false),
        other => Err(Error::Data {
            path: path.to_path_buf(),
            line,
            msg: format!(
                "first column is `{}`: it must be `omega_rad_s` or `freq_hz`",
                crate::util::echo(other.unwrap_or(""))
            ),
        }),
    }
}

/// A hint for a number written with a decimal comma (`1,5` in a `;`-separated file).
pub fn decimal_hint(field: &str) -> &'static str {
    if field.contains(',') {
        ": write the decimal point as `.`"
    } else {
        ""
    }
}

/// Reads a whole text file as UTF-8 (a UTF-8 byte-order mark is dropped, UTF-16 with a
/// byte-order mark is decoded).  Text that is not UTF-8 is an error naming its line.
pub fn read_text(path: &Path) -> Result<String> {
    let bytes = crate::util::read_regular(path, crate::util::MAX_DATA_FILE)?;
    let bytes = decode_utf16(bytes, path)?;
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => Ok(s.to_owned()),
        Err(e) => Err(not_utf8(path, bytes, e.valid_up_to())),
    }
}

fn not_utf8(path: &Path, bytes: &[u8], at: usize) -> Error {
    let line = 1 + bytes[..at].iter().filter(|b| **b == b'\n').count();
    Error::Data {
        path: path.to_path_buf(),
        line,
        msg: format!(
            "not UTF-8 text (byte 0x{:02x}): is this a CSV file? save it as UTF-8 CSV",
            bytes[at]
        ),
    }
}

/// UTF-16 with a byte-order mark, decoded to UTF-8; other bytes unchanged.
fn decode_utf16(bytes: Vec<u8>, path: &Path) -> Result<Vec<u8>> {
    let le = match bytes.get(..2) {
        Some([0xFF, 0xFE]) => true,
        Some([0xFE, 0xFF]) => false,
        _ => return Ok(bytes),
    };
    let units = bytes[2..].chunks(2).map(|c| match (c, le) {
        ([a, b], true) => u16::from_le_bytes([*a, *b]),
        ([a, b], false) => u16::from_be_bytes([*a, *b]),
        _ => 0xFFFF, // odd length: invalid below
    });
    let mut out = String::with_capacity(bytes.len() / 2);
    for (k, c) in char::decode_utf16(units).enumerate() {
        match c {
            Ok('\u{FFFF}') | Err(_) => {
                return Err(Error::Data {
                    path: path.to_path_buf(),
                    line: 1 + out.matches('\n').count(),
                    msg: format!("invalid UTF-16 (code unit {k}): save the file as UTF-8 CSV"),
                })
            }
            Ok(c) => out.push(c),
        }
    }
    Ok(out.into_bytes())
}

/// A streaming CSV table reader: the header is read on construction, then
/// [`next_row`](Self::next_row) advances through the data rows, one reused buffer.
///
/// The records are split by `csv_core`, the parser of the `csv` crate, driven here rather
/// than through `csv::Reader` because that reader positions a record where its search began
/// (before any skipped comment and blank lines), and every message here must name the line
/// the record is on.
pub struct TableReader<'r> {
    path: PathBuf,
    input: Box<dyn BufRead + 'r>,
    core: csv_core::Reader,
    /// 1-based line of the next unread byte.
    line: usize,
    /// The current record's fields, concatenated and UTF-8 checked.
    text: String,
    bytes: Vec<u8>,
    ends_buf: Vec<usize>,
    /// End offset of each field in `text`.
    ends: Vec<usize>,
    /// Line of the header.
    pub header_line: usize,
    /// Column names, trimmed.
    pub names: Vec<String>,
}

impl<'r> TableReader<'r> {
    /// Opens `path` and reads its header.
    pub fn open(path: &Path, expected_header: &str) -> Result<TableReader<'static>> {
        let file = crate::util::open_regular(path)?;
        TableReader::new(file, path, expected_header)
    }

    /// Reads the header from `input`; `path` names it in messages and `expected_header`
    /// is quoted in the message for an empty file.
    pub fn new(input: impl Read + 'r, path: &Path, expected_header: &str) -> Result<Self> {
        let io = |source| Error::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut input = BufReader::with_capacity(1 << 16, input);
        let start = input.fill_buf().map_err(io)?;
        let input: Box<dyn BufRead + 'r> =
            if start.starts_with(&[0xFF, 0xFE]) || start.starts_with(&[0xFE, 0xFF]) {
                let mut all = Vec::new();
                input.read_to_end(&mut all).map_err(io)?;
                Box::new(Cursor::new(decode_utf16(all, path)?))
            } else {
                if start.starts_with(b"\xEF\xBB\xBF") {
                    input.consume(3);
                }
                Box::new(input)
            };
        let mut reader = Self {
            path: path.to_path_buf(),
            input,
            core: csv_core::Reader::new(),
            line: 1,
            text: String::new(),
            bytes: vec![0; 256],
            ends_buf: vec![0; 16],
            ends: Vec::new(),
            header_line: 0,
            names: Vec::new(),
        };
        reader.skip_blank_and_comment_lines()?;
        // The separator is `,` unless the header line has none and has `;` or a tab.
        let head = reader.input.fill_buf().map_err(io)?;
        let head = &head[..head.iter().position(|b| *b == b'\n').unwrap_or(head.len())];
        let delimiter = [b',', b';', b'\t']
            .into_iter()
            .find(|d| head.contains(d))
            .unwrap_or(b',');
        reader.core = csv_core::ReaderBuilder::new().delimiter(delimiter).build();
        let Some(line) = reader.next_record()? else {
            return Err(reader.err(
                1,
                format!("empty file: expected a header such as `{expected_header}`"),
            ));
        };
        let mut names: Vec<String> = reader.fields().map(str::to_owned).collect();
        while names.len() > 1 && names.last().is_some_and(|n| n.is_empty()) {
            names.pop();
        }
        reader.header_line = line;
        reader.names = names;
        Ok(reader)
    }

    /// Consumes line ends, `#` comment lines and lines of blanks before a record.
    fn skip_blank_and_comment_lines(&mut self) -> Result<()> {
        loop {
            let buf = self.input.fill_buf().map_err(|e| io_err(&self.path, e))?;
            let Some(&b) = buf.first() else {
                return Ok(());
            };
            let blank = buf
                .iter()
                .position(|c| !matches!(c, b' ' | b'\t'))
                .is_some_and(|k| matches!(buf[k], b'\n' | b'\r' | b'#'));
            if b == b'#' || blank {
                // Consumed piecewise: a comment line of any length costs no memory.
                loop {
                    let buf = self.input.fill_buf().map_err(|e| io_err(&self.path, e))?;
                    if buf.is_empty() {
                        break;
                    }
                    match buf.iter().position(|c| *c == b'\n') {
                        Some(k) => {
                            self.input.consume(k + 1);
                            self.line += 1;
                            break;
                        }
                        None => {
                            let n = buf.len();
                            self.input.consume(n);
                        }
                    }
                }
            } else if b == b'\n' || b == b'\r' {
                self.input.consume(1);
                self.line += (b == b'\n') as usize;
            } else {
                return Ok(());
            }
        }
    }

    /// The next non-blank, non-comment record and its line.
    fn next_record(&mut self) -> Result<Option<usize>> {
        use csv_core::ReadRecordResult as R;
        loop {
            self.skip_blank_and_comment_lines()?;
            let start = self.line;
            let (mut nout, mut nend) = (0, 0);
            let found = loop {
                let buf = self.input.fill_buf().map_err(|e| io_err(&self.path, e))?;
                let (res, nin, o, e) = (self.core).read_record(
                    buf,
                    &mut self.bytes[nout..],
                    &mut self.ends_buf[nend..],
                );
                self.line += buf[..nin].iter().filter(|c| **c == b'\n').count();
                self.input.consume(nin);
                nout += o;
                nend += e;
                match res {
                    R::InputEmpty => {}
                    R::OutputFull if self.bytes.len() >= MAX_RECORD_BYTES => {
                        return Err(self.err(
                            start,
                            format!(
                                "a line longer than {} MB: is this a CSV file of numbers?",
                                MAX_RECORD_BYTES >> 20
                            ),
                        ));
                    }
                    R::OutputFull => self.bytes.resize(2 * self.bytes.len(), 0),
                    R::OutputEndsFull if self.ends_buf.len() >= MAX_RECORD_FIELDS => {
                        return Err(self.err(start, format!(
                            "more than {MAX_RECORD_FIELDS} fields on one line: is this a CSV file of numbers?"
                        )));
                    }
                    R::OutputEndsFull => self.ends_buf.resize(2 * self.ends_buf.len(), 0),
                    R::Record => break true,
                    R::End => break false,
                }
            };
            if !found {
                return Ok(None);
            }
            self.ends.clear();
            self.ends.extend_from_slice(&self.ends_buf[..nend]);
            let text = std::str::from_utf8(&self.bytes[..nout]).map_err(|_| {
                self.err(
                    start,
                    "not UTF-8 text: is this a CSV file? save it as UTF-8 CSV".into(),
                )
            })?;
            self.text.clear();
            self.text.push_str(text);
            if self.fields().all(str::is_empty) || self.field(0).starts_with('#') {
                continue;
            }
            if self.text.contains(['\n', '\r']) {
                let k = (0..self.ends.len())
                    .find(|&k| self.field(k).contains(['\n', '\r']))
                    .unwrap_or(0);
                return Err(self.err(
                    start,
                    format!(
                        "field {} runs over several lines (a `\"` without its closing `\"`?): close or remove the quote",
                        k + 1
                    ),
                ));
            }
            if self.text.contains('\0') {
                return Err(self.err(
                    start,
                    "NUL byte: the file is binary or UTF-16 without a byte-order mark; save it as UTF-8 CSV"
                        .into(),
                ));
            }
            return Ok(Some(start));
        }
    }

    /// Advances to the next data row and returns its line, `None` at the end.  The row has
    /// exactly `names.len()` fields (trailing empty fields beyond the header are dropped).
    pub fn next_row(&mut self) -> Result<Option<usize>> {
        let Some(line) = self.next_record()? else {
            return Ok(None);
        };
        let n = self.names.len();
        if self.ends.len() > n && self.fields().skip(n).all(str::is_empty) {
            self.ends.truncate(n);
        }
        if self.ends.len() != n {
            return Err(self.err(
                line,
                format!(
                    "{} fields, the header has {}: give every row one value per column",
                    self.ends.len(),
                    n
                ),
            ));
        }
        Ok(Some(line))
    }

    /// The fields of the current row, trimmed.
    pub fn fields(&self) -> impl Iterator<Item = &str> + '_ {
        (0..self.ends.len()).map(|k| self.field(k))
    }

    /// Field `k` of the current row, trimmed (empty beyond the row's width).  A field
    /// quoted after leading blanks (`a, "b"`, which CSV reads as the literal ` "b"`) is
    /// unquoted too.
    pub fn field(&self, k: usize) -> &str {
        match self.ends.get(k) {
            Some(&end) => {
                let start = if k == 0 { 0 } else { self.ends[k - 1] };
                let f = self.text[start..end].trim();
                (f.len() >= 2 && f.starts_with('"') && f.ends_with('"'))
                    .then(|| &f[1..f.len() - 1])
                    .filter(|inner| !inner.contains('"'))
                    .map_or(f, str::trim)
            }
            None => "",
        }
    }

    /// An error at `line` of this file.
    pub fn err(&self, line: usize, msg: String) -> Error {
        Error::Data {
            path: self.path.clone(),
            line,
            msg,
        }
    }

    /// Whether the first column is `freq_hz` (true) or `omega_rad_s` (false).
    pub fn first_column_is_hz(&self) -> Result<bool> {
        first_column_is_hz(&self.path, self.header_line, &self.names)
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Longest record (a line, or lines joined by quotes) read: a file without line ends is not
/// read whole, and no message quotes more than a few dozen characters of it.
pub const MAX_RECORD_BYTES: usize = 1 << 20;

/// Most fields on one line (far beyond any FRF's `2·p·m + 2` columns).
pub const MAX_RECORD_FIELDS: usize = 1 << 16;

fn io_err(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

#[cfg(test)]
mod tests;
