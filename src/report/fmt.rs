//! Number and message formatting shared by the reports, the figures and the CLI: one place
//! decides how a frequency or a ratio prints, so tables, SVG labels and messages agree.

/// Folds a message onto one line (errors are printed and stored as one line each).
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The message with every decimal number of more than 17 digits (a `1e300` printed in full
/// by `{}`: 301 digits) written in short scientific form (`1e300`, `1.234568e-300`); other
/// text, and digit runs inside words (hashes, file names), unchanged.
pub fn short_numbers(msg: &str) -> String {
    let chars: Vec<char> = msg.chars().collect();
    let mut out = String::with_capacity(msg.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let in_word = i > 0 && (chars[i - 1].is_alphanumeric() || chars[i - 1] == '_');
        if !c.is_ascii_digit() || in_word {
            out.push(c);
            i += 1;
            continue;
        }
        let start = i;
        while i < chars.len() && chars[i].is_ascii_digit() {
            i += 1;
        }
        if i + 1 < chars.len() && chars[i] == '.' && chars[i + 1].is_ascii_digit() {
            i += 1;
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
            }
        }
        let token: String = chars[start..i].iter().collect();
        let digits = token.chars().filter(char::is_ascii_digit).count();
        let followed_by_word = i < chars.len() && (chars[i].is_alphabetic() || chars[i] == '_');
        match token.parse::<f64>() {
            Ok(x) if digits > 17 && !followed_by_word => {
                let sci = format!("{x:.6e}");
                let (mant, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
                let mant = if mant.contains('.') {
                    mant.trim_end_matches('0').trim_end_matches('.')
                } else {
                    mant
                };
                out.push_str(&format!("{mant}e{exp}"));
            }
            _ => out.push_str(&token),
        }
    }
    out
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

/// A list of flagged frequencies for the terminal, with its unit: every value when there are
/// few (`1, 2.5 rad/s`), else the bands of consecutive data with their counts
/// (`1–56.8 rad/s (205 data), 60 rad/s`).  `all` are the data frequencies (sorted), `flagged`
/// a subset of them.
pub fn fmt_omegas(all: &[f64], flagged: &[f64]) -> String {
    if flagged.len() <= 12 {
        return flagged
            .iter()
            .map(|w| fmt_g(*w))
            .collect::<Vec<_>>()
            .join(", ")
            + " rad/s";
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
                format!("{} rad/s", fmt_g(*lo))
            } else {
                format!("{}–{} rad/s ({n} data)", fmt_g(*lo), fmt_g(*hi))
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// A number with 4 significant digits (fixed notation from 1e-3 to 1e6, else scientific);
/// a non-finite value prints as `no fit` (never `inf` or `NaN` in a report).
pub fn sig(x: f64) -> String {
    if !x.is_finite() {
        return "no fit".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let d = (3 - x.abs().log10().floor() as i32).max(0) as usize;
    if x.abs() >= 1e-3 && x.abs() < 1e6 {
        format!("{x:.d$}")
    } else {
        format!("{x:.3e}")
    }
}

/// A frequency in rad/s with Hz beside it, 4 significant digits each.
pub fn fmt_w(w: f64) -> String {
    if !w.is_finite() {
        return "no fit".into();
    }
    format!("{} rad/s ({} Hz)", sig(w), sig(w / std::f64::consts::TAU))
}

/// A relative change `x − 1` as a signed percentage with 3 significant digits
/// (`+12.3 %`, `−0.412 %`); beyond ±1e4 % it prints as a factor (`×250`), and a non-finite
/// ratio as `no fit`.
pub fn fmt_change(ratio: f64) -> String {
    if !ratio.is_finite() {
        return "no fit".into();
    }
    let pct = 100.0 * (ratio - 1.0);
    if pct.abs() >= 1e4 {
        return format!("×{}", sig(ratio));
    }
    if pct == 0.0 {
        return "+0 %".into();
    }
    let mag = pct.abs().log10().floor() as i32;
    let mut d = (2 - mag).clamp(0, 3) as usize;
    // −9.9999 rounds to −10.0: one decimal fewer once rounding carries into the next decade.
    let scale = 10f64.powi(d as i32);
    if d > 0 && (pct.abs() * scale).round() / scale >= 10f64.powi(mag + 1) {
        d -= 1;
    }
    format!("{pct:+.d$} %")
}

/// A share in `[0, 1]` as a percentage with one decimal.
pub fn fmt_pct(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    format!("{:.1} %", 100.0 * x)
}

/// `s` in at most `max` characters: cut in the middle with `…` when longer, so that both its
/// beginning and its end stay readable (a long model name keeps its distinguishing tail).
pub fn ellipsize_middle(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    if max == 0 {
        return String::new();
    }
    let keep = max - 1;
    let head = keep.div_ceil(2);
    let tail = keep - head;
    let first: String = s.chars().take(head).collect();
    let last: String = s.chars().skip(n - tail).collect();
    format!("{first}…{last}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_are_shortened() {
        let big = format!("x = {} rad/s", 1e300);
        assert_eq!(short_numbers(&big), "x = 1e300 rad/s");
        let small = format!("y = {}; z = 12.5", 1.25e-300);
        assert_eq!(short_numbers(&small), "y = 1.25e-300; z = 12.5");
        let kept = "file run_12345678901234567890.csv, line 12345678901234567890x";
        assert_eq!(short_numbers(kept), kept);
    }

    #[test]
    fn numbers_print_with_sensible_digits_and_never_as_inf() {
        assert_eq!(sig(1234.5678), "1235");
        assert_eq!(sig(0.012345), "0.01235");
        assert_eq!(sig(7.5e45), "7.500e45");
        assert_eq!(sig(f64::INFINITY), "no fit");
        assert_eq!(fmt_change(1.05), "+5.00 %");
        assert_eq!(fmt_change(0.9), "-10.0 %");
        assert_eq!(fmt_change(1.6e56), "×1.600e56");
        assert_eq!(fmt_change(f64::NAN), "no fit");
        assert_eq!(fmt_w(f64::INFINITY), "no fit");
        assert_eq!(fmt_pct(0.1234), "12.3 %");
    }
}
