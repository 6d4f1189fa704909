//! `summary.csv` of a batch: one row per dataset, in dataset order.
//!
//! Columns: `index` (0-based position in the full list), `name`, `status` (`ok` or
//! `failed`), `n_data`, `max_r_min` (`inf` when some datum has no admissible `r`),
//! `consistent` (`true`/`false` for the configured `r`, empty without one or on failure),
//! `verdict` (why: `consistent`, `inconsistent` or `not_admissible` when A1 fails, so a
//! `consistent=false, n_failing=0` row says its reason), `n_failing` (data the configured `r` does not explain), `data` (the file), `error` (one
//! line, empty on success).

use super::runner::DatasetResult;
use crate::data::table::TableReader;
use crate::error::{Error, Result};
use crate::report::csv::num;
use std::fmt::Write;

/// The header line.
pub const HEADER: &str =
    "index,name,status,n_data,max_r_min,consistent,verdict,n_failing,data,error";

/// One row of `summary.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryRow {
    /// Position in the full list.
    pub index: usize,
    /// Dataset name.
    pub name: String,
    /// True when processed.
    pub ok: bool,
    /// Number of data.
    pub n_data: usize,
    /// Largest `r_min`.
    pub max_r_min: Option<f64>,
    /// Verdict for the configured `r`.
    pub consistent: Option<bool>,
    /// Why (`not_admissible` when A1 fails at some datum).
    pub verdict: Option<crate::consistency::Verdict>,
    /// Number of data not explained by the configured `r`.
    pub n_failing: usize,
    /// The data file.
    pub data: String,
    /// The error, on one line.
    pub error: String,
}

impl From<&DatasetResult> for SummaryRow {
    fn from(r: &DatasetResult) -> Self {
        SummaryRow {
            index: r.index,
            name: r.name.clone(),
            ok: r.ok(),
            n_data: r.n_data,
            max_r_min: r.max_r_min,
            consistent: r.consistent,
            verdict: r.verdict,
            n_failing: r.failing_omegas.len(),
            data: r.path.display().to_string(),
            error: r.error.clone().unwrap_or_default(),
        }
    }
}

/// Quotes a CSV field when needed.
pub fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\"").replace(['\n', '\r'], " "))
    } else {
        s.to_string()
    }
}

/// Renders `summary.csv`.
pub fn render(rows: &[SummaryRow]) -> String {
    let mut s = format!("{HEADER}\n");
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{}",
            r.index,
            quote(&r.name),
            if r.ok { "ok" } else { "failed" },
            r.n_data,
            r.max_r_min.map_or(String::new(), num),
            r.consistent.map_or(String::new(), |c| c.to_string()),
            r.verdict.map_or("", |v| v.as_str()),
            r.n_failing,
            quote(&r.data),
            quote(&r.error)
        );
    }
    s
}

/// Parses `summary.csv` (for `rshape merge`).
pub fn parse(text: &str, what: &str) -> Result<Vec<SummaryRow>> {
    let bad = |line: usize, m: String| Error::Invalid(format!("{what}:{line}: {m}"));
    let mut table = TableReader::new(text.as_bytes(), std::path::Path::new(what), HEADER)
        .map_err(|e| bad(1, e.to_string()))?;
    if table.names.join(",") != HEADER {
        return Err(bad(
            table.header_line,
            format!("not a summary.csv: the header must be `{HEADER}`"),
        ));
    }
    let mut rows = Vec::new();
    // The csv crate's parser: quoted names, paths and error messages with commas and `""`.
    while let Some(line) = table
        .next_row()
        .map_err(|e| Error::Invalid(e.to_string()))?
    {
        let f: Vec<String> = table.fields().map(str::to_owned).collect();
        let k = line - 1;
        let int = |s: &str| {
            s.parse::<usize>()
                .map_err(|_| bad(k + 1, format!("`{s}` is not a count")))
        };
        rows.push(SummaryRow {
            index: int(&f[0])?,
            name: f[1].clone(),
            ok: match f[2].as_str() {
                "ok" => true,
                "failed" => false,
                s => return Err(bad(k + 1, format!("status `{s}` is neither ok nor failed"))),
            },
            n_data: int(&f[3])?,
            max_r_min: match f[4].as_str() {
                "" => None,
                "inf" => Some(f64::INFINITY),
                s => Some(
                    s.parse()
                        .map_err(|_| bad(k + 1, format!("`{s}` is not a number")))?,
                ),
            },
            consistent: match f[5].as_str() {
                "true" => Some(true),
                "false" => Some(false),
                _ => None,
            },
            verdict: match f[6].as_str() {
                "consistent" => Some(crate::consistency::Verdict::Consistent),
                "inconsistent" => Some(crate::consistency::Verdict::Inconsistent),
                "not_admissible" => Some(crate::consistency::Verdict::NotAdmissible),
                _ => None,
            },
            n_failing: int(&f[7])?,
            data: f[8].clone(),
            error: f[9].clone(),
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let mut rows = vec![SummaryRow {
            index: 3,
            name: "a,b".into(),
            ok: false,
            n_data: 0,
            max_r_min: None,
            consistent: None,
            verdict: None,
            n_failing: 0,
            data: "x.csv".into(),
            error: "x.csv:3: bad \"number\"".into(),
        }];
        rows.push(SummaryRow {
            index: 4,
            name: "b".into(),
            ok: true,
            n_data: 3,
            max_r_min: Some(0.5),
            consistent: Some(false),
            verdict: Some(crate::consistency::Verdict::NotAdmissible),
            n_failing: 0,
            data: "y.csv".into(),
            error: String::new(),
        });
        assert_eq!(parse(&render(&rows), "s").unwrap(), rows);
    }
}
