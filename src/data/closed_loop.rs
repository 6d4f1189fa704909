//! Closed-loop data files (Crowder & de Callafon, eqs. (8)–(9)).
//!
//! Two forms, told apart by the header:
//! * the closed-loop FRF `Φ_cl = Y/R` (reference → output) in the ordinary FRF format
//!   (`omega_rad_s` or `freq_hz`, then `re_i_j,im_i_j` or `mag_i_j,phase_deg_i_j`, optional
//!   `noise_radius`), read by [`crate::data::read_frf_csv`];
//! * the spectra of a SISO experiment: `freq_hz` (or `omega_rad_s`), `re_y,im_y,re_r,im_r`
//!   (the DFTs `Y(ω)`, `R(ω)` at the excited frequencies), optional `noise_radius`.  The
//!   datum is `Φ = Y/R`; `R(ω) = 0` at a row is an error naming the line.
//!
//! In both forms `noise_radius` is `|W_cl(jω)|` of eq. (8), a radius on `Φ = Y/R`
//! (`Y = (Φ + W_cl δ)R`); a bound `b` on `|Y|`'s noise is the radius `b/|R|`.

use super::frf::FrfData;
use super::reader::parse_frf_csv;
use super::table::Table;
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::path::Path;

/// The spectra columns.
pub const SPECTRA_COLUMNS: [&str; 4] = ["re_y", "im_y", "re_r", "im_r"];

/// Reads closed-loop data (FRF or `Y`/`R` spectra); every error names the file and line.
pub fn read_closed_loop_csv(path: &Path) -> Result<FrfData> {
    let text = super::table::read_text(path)?;
    parse_closed_loop_csv(&text, path)
}

/// Parses closed-loop data text; `path` is used in messages.
pub fn parse_closed_loop_csv(text: &str, path: &Path) -> Result<FrfData> {
    let table = Table::parse(text, path, "freq_hz,re_y,im_y,re_r,im_r")?;
    let is_spectrum = |n: &str| {
        n.starts_with("re_y")
            || n.starts_with("im_y")
            || n.starts_with("re_r")
            || n.starts_with("im_r")
    };
    if !table.names.iter().any(|n| is_spectrum(n)) {
        return parse_frf_csv(text, path);
    }
    let hline = table.header_line;
    let hz = table.first_column_is_hz()?;
    let mut col = [usize::MAX; 4];
    let mut noise_col = None;
    for (k, name) in table.names.iter().enumerate().skip(1) {
        if *name == "noise_radius" {
            noise_col = Some(k);
        } else if let Some(i) = SPECTRA_COLUMNS.iter().position(|c| c == name) {
            if col[i] != usize::MAX {
                return Err(table.err(hline, format!("column `{name}` appears twice")));
            }
            col[i] = k;
        } else {
            return Err(table.err(
                hline,
                format!(
                    "unknown column `{name}`: spectra files have re_y,im_y,re_r,im_r (one SISO experiment) and optionally noise_radius; give MIMO closed-loop data as an FRF (re_i_j,im_i_j)"
                ),
            ));
        }
    }
    if let Some(i) = col.iter().position(|c| *c == usize::MAX) {
        return Err(table.err(
            hline,
            format!(
                "missing column `{}`: spectra files need re_y,im_y,re_r,im_r",
                SPECTRA_COLUMNS[i]
            ),
        ));
    }
    let mut rows: Vec<(f64, Complex64, Complex64, Option<f64>, usize)> = Vec::new();
    for (line, fields) in &table.rows {
        let line = *line;
        let num = |c: usize| -> Result<f64> {
            let v: f64 = fields[c].parse().map_err(|_| {
                table.err(
                    line,
                    format!(
                        "column `{}`: `{}` is not a number{}",
                        table.names[c],
                        fields[c],
                        super::table::decimal_hint(fields[c])
                    ),
                )
            })?;
            if !v.is_finite() {
                return Err(table.err(
                    line,
                    format!(
                        "column `{}`: value `{}` is not finite",
                        table.names[c], fields[c]
                    ),
                ));
            }
            Ok(v)
        };
        let f = num(0)?;
        if f <= 0.0 {
            return Err(table.err(line, format!("frequency {f} must be positive")));
        }
        let omega = if hz { std::f64::consts::TAU * f } else { f };
        let y = Complex64::new(num(col[0])?, num(col[1])?);
        let r = Complex64::new(num(col[2])?, num(col[3])?);
        let noise = match noise_col {
            Some(c) => {
                let v = num(c)?;
                if v < 0.0 {
                    return Err(table.err(line, format!("noise_radius {v} is negative")));
                }
                Some(v)
            }
            None => None,
        };
        rows.push((omega, y, r, noise, line));
    }
    if rows.is_empty() {
        return Err(table.err(hline, "no data rows after the header".into()));
    }
    // R(ω) = 0 (or negligible against the file's largest |R|): the reference did not excite
    // this frequency, so Y/R is not a measurement.
    let r_peak = rows.iter().map(|r| r.2.norm()).fold(0.0, f64::max);
    for (omega, y, r, _, line) in &rows {
        let q = *y / *r;
        if r.norm() <= 1e-12 * r_peak || !q.is_finite() {
            return Err(table.err(
                *line,
                format!(
                    "R(ω) = {} at omega = {omega} rad/s: the reference has no energy at this frequency, so Y/R is undefined; drop the row",
                    r.norm()
                ),
            ));
        }
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in rows.windows(2) {
        if w[1].0 <= w[0].0 * (1.0 + 1e-12) {
            return Err(table.err(
                w[1].4.max(w[0].4),
                format!(
                    "duplicate frequency {} rad/s (also on line {}): each frequency must appear once",
                    w[1].0,
                    w[1].4.min(w[0].4)
                ),
            ));
        }
    }
    Ok(FrfData {
        path: path.to_path_buf(),
        omega: rows.iter().map(|r| r.0).collect(),
        response: rows
            .iter()
            .map(|r| DMatrix::from_element(1, 1, r.1 / r.2))
            .collect(),
        noise_radius: noise_col.map(|_| rows.iter().map(|r| r.3.unwrap_or(0.0)).collect()),
        lines: rows.iter().map(|r| r.4).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectra_give_y_over_r_and_frf_files_pass_through() {
        let p = Path::new("cl.csv");
        let d = parse_closed_loop_csv(
            "# comment\nomega_rad_s,re_y,im_y,re_r,im_r,noise_radius\n2,1,1,0,2,0.1\n1,3,0,1.5,0,0\n",
            p,
        )
        .unwrap();
        assert_eq!(d.omega, vec![1.0, 2.0]);
        assert_eq!(d.response[0][(0, 0)], Complex64::new(2.0, 0.0));
        assert_eq!(d.response[1][(0, 0)], Complex64::new(0.5, -0.5));
        assert_eq!(d.noise_radius, Some(vec![0.0, 0.1]));
        assert_eq!(d.lines, vec![4, 3]);
        let f = parse_closed_loop_csv("omega_rad_s,re_1_1,im_1_1\n1,0.5,0\n", p).unwrap();
        assert_eq!(f.response[0][(0, 0)], Complex64::new(0.5, 0.0));
    }

    #[test]
    fn zero_reference_and_bad_columns_name_the_line() {
        let p = Path::new("cl.csv");
        let e = parse_closed_loop_csv("freq_hz,re_y,im_y,re_r,im_r\n1,1,0,1,0\n2,1,0,0,0\n", p)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("cl.csv:3:") && e.contains("R(ω) = 0"), "{e}");
        let e = parse_closed_loop_csv("freq_hz,re_y,im_y,re_r\n1,1,0,1\n", p)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("cl.csv:1:") && e.contains("missing column `im_r`"),
            "{e}"
        );
        let e = parse_closed_loop_csv(
            "freq_hz,re_y_1,im_y_1,re_y_2,im_y_2,re_r,im_r\n1,1,0,1,0,1,0\n",
            p,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("unknown column `re_y_1`"), "{e}");
        let e = parse_closed_loop_csv("freq_hz,re_y,im_y,re_r,im_r\n1,1,0,1\n", p)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("cl.csv:2:"), "{e}");
    }
}
