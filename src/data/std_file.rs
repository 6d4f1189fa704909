//! Readers of per-frequency FRF quality files, converted to noise radii: standard
//! deviations (`freq_hz` or `omega_rad_s`, then `std_i_j` columns; radius = factor·std, e.g.
//! 3σ) and ordinary coherences of an H1 estimate (`coh_i_j` columns; radius from the random
//! error of H1, [`h1_random_error`]).

use super::table::Table;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

/// Per-frequency standard deviations of an FRF.
#[derive(Debug, Clone)]
pub struct StdData {
    /// Frequencies in rad/s, in file order.
    pub omega: Vec<f64>,
    /// `std[(i, j)]` per row, keyed by the 1-based (output, input).
    pub std: HashMap<(usize, usize), Vec<f64>>,
    /// 1-based file line of each row.
    pub lines: Vec<usize>,
}

/// Reads a std file; every error names the file and the line.
pub fn read_std_csv(path: &Path) -> Result<StdData> {
    read_columns(path, "std", |_| None)
}

/// Reads a coherence file (`freq_hz` or `omega_rad_s`, then `coh_i_j` columns, the ordinary
/// coherence γ² of entry (i, j)); every error names the file and the line.  The values are
/// in [`StdData::std`], keyed like a std file's.
///
/// **Rule:** a coherence must lie in (0, 1]; anything else (0, negative, above 1, not a
/// number) is refused, not clamped: γ² = 0 means the response is not linearly related to
/// the force at all (infinite random error) and γ² > 1 is impossible for an estimate from
/// averaged spectra, so either points to a wrong file or column.
pub fn read_coherence_csv(path: &Path) -> Result<StdData> {
    read_columns(path, "coh", |v| {
        (v <= 0.0 || v > 1.0).then(|| {
            format!(
                "{v} is not a coherence in (0, 1] (γ² = 0 means no linear relation: drop the line; γ² > 1 means a wrong column)"
            )
        })
    })
}

/// The normalized random error of the magnitude of an H1 estimate from `n` averages with
/// ordinary coherence `γ²` (Bendat & Piersol, *Random Data*, 4th ed., Table 9.6, eq. (9.73)):
/// `ε = √(1 − γ²) / (|γ|·√(2n))`.  For γ² = 1 it is 0.
pub fn h1_random_error(coherence: f64, averages: u32) -> f64 {
    ((1.0 - coherence).max(0.0) / (coherence * 2.0 * f64::from(averages))).sqrt()
}

/// Reads a file of `<prefix>_i_j` columns; `check(v)` says why a value (not the frequency)
/// is refused.
fn read_columns(
    path: &Path,
    prefix: &str,
    check: impl Fn(f64) -> Option<String>,
) -> Result<StdData> {
    let text = super::table::read_text(path)?;
    let table = Table::parse(&text, path, &format!("freq_hz,{prefix}_1_1"))?;
    let err = |line: usize, msg: String| table.err(line, msg);
    let (hline, names) = (table.header_line, &table.names);
    let hz = table.first_column_is_hz()?;
    let mut cols = Vec::new();
    for name in &names[1..] {
        let key = name
            .strip_prefix(prefix)
            .and_then(|r| r.strip_prefix('_'))
            .and_then(|r| r.split_once('_'))
            .and_then(|(i, j)| Some((i.parse::<usize>().ok()?, j.parse::<usize>().ok()?)))
            .filter(|(i, j)| *i >= 1 && *j >= 1)
            .ok_or_else(|| {
                err(
                    hline,
                    format!("unknown column `{name}`: expected {prefix}_i_j"),
                )
            })?;
        cols.push(key);
    }
    let mut out = StdData {
        omega: Vec::new(),
        std: cols.iter().map(|k| (*k, Vec::new())).collect(),
        lines: Vec::new(),
    };
    for (line, fields) in &table.rows {
        let line = *line;
        let mut vals = Vec::with_capacity(fields.len());
        for (c, f) in fields.iter().enumerate() {
            let v: f64 = f.parse().map_err(|_| {
                err(
                    line,
                    format!(
                        "column `{}`: `{f}` is not a number{}",
                        names[c],
                        super::table::decimal_hint(f)
                    ),
                )
            })?;
            if !v.is_finite() || v < 0.0 || (c == 0 && v <= 0.0) {
                return Err(err(
                    line,
                    format!("column `{}`: {v} must be finite and ≥ 0", names[c]),
                ));
            }
            if let Some(why) = (c > 0).then(|| check(v)).flatten() {
                return Err(err(line, format!("column `{}`: {why}", names[c])));
            }
            vals.push(v);
        }
        out.omega.push(if hz {
            2.0 * std::f64::consts::PI * vals[0]
        } else {
            vals[0]
        });
        out.lines.push(line);
        for (k, key) in cols.iter().enumerate() {
            out.std.get_mut(key).expect("column").push(vals[k + 1]);
        }
    }
    Ok(out)
}

impl StdData {
    /// The std of entry `(out, inp)` (1-based) at each of `omega` (matched within a relative
    /// 1e-6), times `factor`.  A frequency missing from the file is an error naming it.
    pub fn radius_at(
        &self,
        path: &Path,
        omega: &[f64],
        out: usize,
        inp: usize,
        factor: f64,
    ) -> Result<Vec<f64>> {
        Ok(self
            .values_at(path, "std", omega, out, inp)?
            .into_iter()
            .map(|s| factor * s)
            .collect())
    }

    /// The values of column `<prefix>_<out>_<inp>` at each of `omega` (matched within a
    /// relative 1e-6).  A frequency missing from the file is an error naming it.
    pub fn values_at(
        &self,
        path: &Path,
        prefix: &str,
        omega: &[f64],
        out: usize,
        inp: usize,
    ) -> Result<Vec<f64>> {
        let col = self.std.get(&(out, inp)).ok_or_else(|| Error::Input {
            path: path.to_path_buf(),
            msg: format!("no column {prefix}_{out}_{inp} for the selected channel"),
        })?;
        omega
            .iter()
            .map(|w| {
                self.omega
                    .iter()
                    .position(|x| (x - w).abs() <= 1e-6 * w)
                    .map(|k| col[k])
                    .ok_or_else(|| {
                        Error::Input {
                            path: path.to_path_buf(),
                            msg: format!(
                                "no {prefix} at omega = {w} rad/s ({} Hz) of the data: the file's frequencies must match the FRF file's",
                                w / (2.0 * std::f64::consts::PI),
                            ),
                        }
                    })
            })
            .collect()
    }
}
