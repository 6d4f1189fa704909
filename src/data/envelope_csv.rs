//! Reader of envelope CSV files for `rshape fit --envelope FILE`: an envelope computed
//! elsewhere, or combined from several experiments.
//!
//! Format: a header naming the columns `omega_rad_s` and `r_min`, and optionally
//! `a1_limit` (any order; other columns are errors), then one row per frequency.  `inf` is
//! allowed in `r_min` (no admissible r explains the datum); an empty `a1_limit` cell means
//! unknown, and the column must then be empty on every row.  Lines starting with `#` are
//! comments.  This reads the `envelope.csv` that `rshape envelope` writes.  Rows are sorted by
//! frequency; duplicate frequencies are errors.  Every error names the file and the line.

use super::table::Table;
use crate::consistency::{Envelope, EnvelopeMethod};
use crate::error::Result;
use std::path::Path;

/// Reads an envelope CSV file.
pub fn read_envelope_csv(path: &Path) -> Result<Envelope> {
    let text = super::table::read_text(path)?;
    parse_envelope_csv(&text, path)
}

fn parse_num(s: &str) -> Option<f64> {
    match s.to_ascii_lowercase().as_str() {
        "inf" | "+inf" | "infinity" => Some(f64::INFINITY),
        t => t.parse::<f64>().ok().filter(|v| v.is_finite()),
    }
}

/// Parses envelope CSV text; `path` is used in messages.
pub fn parse_envelope_csv(text: &str, path: &Path) -> Result<Envelope> {
    let table = Table::parse(text, path, "omega_rad_s,r_min[,a1_limit]")?;
    let err = |line: usize, msg: String| table.err(line, msg);
    let hline = table.header_line;
    let (mut cw, mut cr, mut ca) = (None, None, None);
    let names = &table.names;
    for (k, name) in names.iter().enumerate() {
        let slot = match *name {
            "omega_rad_s" => &mut cw,
            "r_min" => &mut cr,
            "a1_limit" => &mut ca,
            other => {
                return Err(err(
                    hline,
                    format!(
                    "unknown column `{other}`: expected omega_rad_s, r_min and optionally a1_limit"
                ),
                ))
            }
        };
        if slot.replace(k).is_some() {
            return Err(err(hline, format!("column `{name}` appears twice")));
        }
    }
    let (Some(cw), Some(cr)) = (cw, cr) else {
        return Err(err(
            hline,
            "the header must name the columns omega_rad_s and r_min".into(),
        ));
    };
    let mut data: Vec<(f64, f64, Option<f64>, usize)> = Vec::new();
    for (line, cells) in &table.rows {
        let line = *line;
        let w = parse_num(cells[cw])
            .filter(|w| w.is_finite() && *w > 0.0)
            .ok_or_else(|| {
                err(
                    line,
                    format!("omega_rad_s `{}` must be a finite number > 0", cells[cw]),
                )
            })?;
        let r = parse_num(cells[cr]).filter(|r| *r >= 0.0).ok_or_else(|| {
            err(
                line,
                format!("r_min `{}` must be a number ≥ 0 or inf", cells[cr]),
            )
        })?;
        let a = match ca {
            Some(c) if !cells[c].is_empty() => Some(
                parse_num(cells[c])
                    .filter(|a| a.is_finite() && *a > 0.0)
                    .ok_or_else(|| {
                        err(
                            line,
                            format!(
                                "a1_limit `{}` must be a finite number > 0 (or empty)",
                                cells[c]
                            ),
                        )
                    })?,
            ),
            _ => None,
        };
        data.push((w, r, a, line));
    }
    if data.is_empty() {
        return Err(err(hline, "no data rows after the header".into()));
    }
    let with_a1 = data.iter().filter(|d| d.2.is_some()).count();
    if with_a1 != 0 && with_a1 != data.len() {
        let line = data.iter().find(|d| d.2.is_none()).map_or(hline, |d| d.3);
        return Err(err(
            line,
            "a1_limit is empty on this row but given on others: give it everywhere or nowhere"
                .into(),
        ));
    }
    data.sort_by(|a, b| a.0.total_cmp(&b.0));
    for k in 1..data.len() {
        if data[k].0 == data[k - 1].0 {
            return Err(err(
                data[k].3.max(data[k - 1].3),
                format!(
                    "frequency {} appears twice (lines {} and {}): combine the envelopes first (take the larger r_min)",
                    data[k].0,
                    data[k - 1].3.min(data[k].3),
                    data[k - 1].3.max(data[k].3)
                ),
            ));
        }
    }
    Ok(Envelope {
        omega: data.iter().map(|d| d.0).collect(),
        r_min: data.iter().map(|d| d.1).collect(),
        a1_limit: (with_a1 > 0).then(|| data.iter().map(|d| d.2.unwrap_or(f64::NAN)).collect()),
        method: EnvelopeMethod::File,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_inf_and_sorts() {
        let t = "# c\nr_min,omega_rad_s\n2,10\ninf,1\n";
        let e = parse_envelope_csv(t, Path::new("e.csv")).unwrap();
        assert_eq!(e.omega, vec![1.0, 10.0]);
        assert!(e.r_min[0].is_infinite());
        assert!(e.a1_limit.is_none());
    }

    #[test]
    fn errors_name_file_and_line() {
        let t = "omega_rad_s,r_min,a1_limit\n1,0.5,2\n2,abc,2\n";
        let e = parse_envelope_csv(t, Path::new("e.csv")).unwrap_err();
        assert!(e.to_string().starts_with("e.csv:3:"), "{e}");
        let t = "omega_rad_s,r_min,a1_limit\n1,0.5,\n2,0.4,\n";
        let e = parse_envelope_csv(t, Path::new("e.csv")).unwrap();
        assert!(e.a1_limit.is_none());
    }
}
