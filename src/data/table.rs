//! The common shape of rshape's CSV inputs (FRF data, std files, envelopes): `#` comments
//! and blank lines skipped, one header, and rows with as many fields as the header.  Every
//! error names the file and the 1-based line.

use crate::error::{Error, Result};
use std::path::Path;

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
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(k, l)| (k + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
        let (header_line, header) = lines.next().ok_or_else(|| Error::Data {
            path: path.to_path_buf(),
            line: 1,
            msg: format!("empty file: expected a header such as `{expected_header}`"),
        })?;
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let mut rows = Vec::new();
        for (line, row) in lines {
            let fields: Vec<&str> = row.split(',').map(str::trim).collect();
            if fields.len() != names.len() {
                return Err(Error::Data {
                    path: path.to_path_buf(),
                    line,
                    msg: format!("{} fields, the header has {}", fields.len(), names.len()),
                });
            }
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
        match self.names[0] {
            "freq_hz" => Ok(true),
            "omega_rad_s" => Ok(false),
            other => Err(self.err(
                self.header_line,
                format!("first column is `{other}`: it must be `omega_rad_s` or `freq_hz`"),
            )),
        }
    }
}
