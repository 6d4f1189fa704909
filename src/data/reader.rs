//! Reader of FRF CSV files.
//!
//! Format: a header, then one row per frequency.  The first column is `omega_rad_s` or
//! `freq_hz` (Hz is converted to rad/s).  Each output `i` and input `j` (1-based) is given as
//! `re_i_j,im_i_j` or `mag_i_j,phase_deg_i_j`.  An optional `noise_radius` column gives a
//! per-frequency noise radius.  Lines starting with `#` are comments.

use super::frf::FrfData;
use super::table::Table;
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::collections::HashMap;
use std::path::Path;

#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
enum Part {
    Re,
    Im,
    Mag,
    PhaseDeg,
}

/// Reads an FRF CSV file; every error names the file and the line.
pub fn read_frf_csv(path: &Path) -> Result<FrfData> {
    let text = super::table::read_text(path)?;
    parse_frf_csv(&text, path)
}

/// Parses FRF CSV text; `path` is used in messages.
pub fn parse_frf_csv(text: &str, path: &Path) -> Result<FrfData> {
    let table = Table::parse(text, path, "freq_hz,re_1_1,im_1_1")?;
    let err = |line: usize, msg: String| table.err(line, msg);
    let (hline, names) = (table.header_line, &table.names);
    let hz = table.first_column_is_hz()?;
    let mut cells: HashMap<(usize, usize, Part), usize> = HashMap::new();
    let mut noise_col = None;
    let (mut p, mut m) = (0, 0);
    for (col, name) in names.iter().enumerate().skip(1) {
        if *name == "noise_radius" {
            noise_col = Some(col);
            continue;
        }
        let parsed = parse_column(name).ok_or_else(|| {
            err(
                hline,
                format!("unknown column `{name}`: expected re_i_j, im_i_j, mag_i_j, phase_deg_i_j or noise_radius"),
            )
        })?;
        if cells.insert(parsed, col).is_some() {
            return Err(err(hline, format!("column `{name}` appears twice")));
        }
        p = p.max(parsed.0);
        m = m.max(parsed.1);
    }
    if p == 0 {
        return Err(err(
            hline,
            "no response columns: add re_1_1,im_1_1 (or mag_1_1,phase_deg_1_1)".into(),
        ));
    }
    // Every (i, j) needs one complete representation.
    let mut layout = vec![(Part::Re, 0usize, 0usize); p * m];
    for i in 1..=p {
        for j in 1..=m {
            let re = (cells.get(&(i, j, Part::Re)), cells.get(&(i, j, Part::Im)));
            let mp = (
                cells.get(&(i, j, Part::Mag)),
                cells.get(&(i, j, Part::PhaseDeg)),
            );
            layout[(i - 1) * m + (j - 1)] = match (re, mp) {
                ((Some(a), Some(b)), (None, None)) => (Part::Re, *a, *b),
                ((None, None), (Some(a), Some(b))) => (Part::Mag, *a, *b),
                ((Some(_), None), _) => {
                    return Err(err(hline, format!("missing column im_{i}_{j}")))
                }
                ((None, Some(_)), _) => {
                    return Err(err(hline, format!("missing column re_{i}_{j}")))
                }
                (_, (Some(_), None)) => {
                    return Err(err(hline, format!("missing column phase_deg_{i}_{j}")))
                }
                (_, (None, Some(_))) => {
                    return Err(err(hline, format!("missing column mag_{i}_{j}")))
                }
                ((None, None), (None, None)) => {
                    return Err(err(
                        hline,
                        format!("missing columns re_{i}_{j},im_{i}_{j} (the data are {p}×{m})"),
                    ))
                }
                _ => {
                    return Err(err(
                        hline,
                        format!(
                            "entry ({i},{j}) is given both as re/im and as mag/phase: keep one"
                        ),
                    ))
                }
            };
        }
    }
    let mut data: Vec<(f64, DMatrix<Complex64>, Option<f64>, usize)> = Vec::new();
    for (line, fields) in &table.rows {
        let line = *line;
        let num = |col: usize| -> Result<f64> {
            let v: f64 = fields[col].parse().map_err(|_| {
                err(
                    line,
                    format!(
                        "column `{}`: `{}` is not a number{}",
                        names[col],
                        fields[col],
                        super::table::decimal_hint(fields[col])
                    ),
                )
            })?;
            if !v.is_finite() {
                return Err(err(
                    line,
                    format!(
                        "column `{}`: value `{}` is not finite",
                        names[col], fields[col]
                    ),
                ));
            }
            Ok(v)
        };
        let f = num(0)?;
        if f <= 0.0 {
            return Err(err(line, format!("frequency {f} must be positive")));
        }
        let omega = if hz {
            2.0 * std::f64::consts::PI * f
        } else {
            f
        };
        let mut phi = DMatrix::zeros(p, m);
        for i in 0..p {
            for j in 0..m {
                let (kind, a, b) = layout[i * m + j];
                let (x, y) = (num(a)?, num(b)?);
                phi[(i, j)] = match kind {
                    Part::Re => Complex64::new(x, y),
                    _ => {
                        if x < 0.0 {
                            return Err(err(
                                line,
                                format!("column `{}`: magnitude {x} is negative", names[a]),
                            ));
                        }
                        Complex64::from_polar(x, y.to_radians())
                    }
                };
            }
        }
        let noise = match noise_col {
            Some(c) => {
                let v = num(c)?;
                if v < 0.0 {
                    return Err(err(line, format!("noise_radius {v} is negative")));
                }
                Some(v)
            }
            None => None,
        };
        data.push((omega, phi, noise, line));
    }
    if data.is_empty() {
        return Err(err(hline, "no data rows after the header".into()));
    }
    data.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in data.windows(2) {
        if w[1].0 <= w[0].0 * (1.0 + 1e-12) {
            return Err(err(
                w[1].3.max(w[0].3),
                format!(
                    "duplicate frequency {} rad/s (also on line {}): each frequency must appear once",
                    w[1].0,
                    w[1].3.min(w[0].3)
                ),
            ));
        }
    }
    Ok(FrfData {
        path: path.to_path_buf(),
        omega: data.iter().map(|d| d.0).collect(),
        response: data.iter().map(|d| d.1.clone()).collect(),
        noise_radius: noise_col.map(|_| data.iter().map(|d| d.2.unwrap_or(0.0)).collect()),
        lines: data.iter().map(|d| d.3).collect(),
    })
}

fn parse_column(name: &str) -> Option<(usize, usize, Part)> {
    let (part, rest) = if let Some(r) = name.strip_prefix("re_") {
        (Part::Re, r)
    } else if let Some(r) = name.strip_prefix("im_") {
        (Part::Im, r)
    } else if let Some(r) = name.strip_prefix("mag_") {
        (Part::Mag, r)
    } else if let Some(r) = name.strip_prefix("phase_deg_") {
        (Part::PhaseDeg, r)
    } else {
        return None;
    };
    let (i, j) = rest.split_once('_')?;
    let (i, j): (usize, usize) = (i.parse().ok()?, j.parse().ok()?);
    (i >= 1 && j >= 1).then_some((i, j, part))
}
