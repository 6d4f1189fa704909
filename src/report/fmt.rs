//! Number and message formatting shared by the reports, the figures and the CLI: one place
//! decides how a frequency or a ratio prints, so tables, SVG labels and messages agree.

/// Folds a message onto one line (errors are printed and stored as one line each).
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Formats a frequency for tables.
pub fn fmt_g(x: f64) -> String {
    if x.is_infinite() {
        "inf".into()
    } else if x == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&x.abs()) {
        format!("{x:.6}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.4e}")
    }
}

/// A list of flagged frequencies for the terminal: every value when there are few, else the
/// bands of consecutive data (`lo–hi`) with their counts.  `all` are the data frequencies
/// (sorted), `flagged` a subset of them.
pub fn fmt_omegas(all: &[f64], flagged: &[f64]) -> String {
    if flagged.len() <= 12 {
        return flagged
            .iter()
            .map(|w| fmt_g(*w))
            .collect::<Vec<_>>()
            .join(", ");
    }
    let mut bands: Vec<(f64, f64, usize)> = Vec::new();
    let mut prev_idx: Option<usize> = None;
    // Both lists are sorted: one forward walk finds every index (linear, not quadratic).
    let mut cursor = 0;
    for w in flagged {
        let idx = all[cursor..]
            .iter()
            .position(|x| x == w)
            .map(|k| cursor + k);
        if let Some(i) = idx {
            cursor = i + 1;
        }
        match (bands.last_mut(), prev_idx, idx) {
            (Some(b), Some(p), Some(i)) if i == p + 1 => {
                b.1 = *w;
                b.2 += 1;
            }
            _ => bands.push((*w, *w, 1)),
        }
        prev_idx = idx;
    }
    bands
        .iter()
        .map(|(lo, hi, n)| {
            if n == &1 {
                fmt_g(*lo)
            } else {
                format!("{}–{} ({n} data)", fmt_g(*lo), fmt_g(*hi))
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}
