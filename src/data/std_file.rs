//! Reader of FRF standard-deviation files (`freq_hz` or `omega_rad_s`, then `std_i_j`
//! columns), converted to per-frequency noise radii with a stated factor (e.g. 3σ).

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
    let text = super::table::read_text(path)?;
    let table = Table::parse(&text, path, "freq_hz,std_1_1")?;
    let err = |line: usize, msg: String| table.err(line, msg);
    let (hline, names) = (table.header_line, &table.names);
    let hz = table.first_column_is_hz()?;
    let mut cols = Vec::new();
    for name in &names[1..] {
        let key = name
            .strip_prefix("std_")
            .and_then(|r| r.split_once('_'))
            .and_then(|(i, j)| Some((i.parse::<usize>().ok()?, j.parse::<usize>().ok()?)))
            .filter(|(i, j)| *i >= 1 && *j >= 1)
            .ok_or_else(|| err(hline, format!("unknown column `{name}`: expected std_i_j")))?;
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
        let col = self.std.get(&(out, inp)).ok_or_else(|| {
            Error::Invalid(format!(
                "{}: no column std_{out}_{inp} for the selected channel",
                path.display()
            ))
        })?;
        omega
            .iter()
            .map(|w| {
                self.omega
                    .iter()
                    .position(|x| (x - w).abs() <= 1e-6 * w)
                    .map(|k| factor * col[k])
                    .ok_or_else(|| {
                        Error::Invalid(format!(
                            "{}: no std at omega = {w} rad/s ({} Hz) of the data",
                            path.display(),
                            w / (2.0 * std::f64::consts::PI)
                        ))
                    })
            })
            .collect()
    }
}
