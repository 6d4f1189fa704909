//! Scans of what `diagnose` writes: every number finite, every frequency (and the frequency
//! of every time constant) within 1e6× of the measured band, no absurd percentage.

use serde_json::Value;

/// Keys whose value is a frequency (rad/s).
const FREQ: [&str; 6] = [
    "omega_n",
    "omega_c",
    "z",
    "pole",
    "separates_above",
    "separates_below",
];
/// Keys whose value is a time (s): `tau_s` (frequency 1/τ), `t_s` (2π/T).
const TIME: [&str; 2] = ["tau_s", "t_s"];
/// Keys that may be `null` (an absent optional value, not a non-finite number).
const MAY_BE_NULL: [&str; 6] = [
    "no_fit",
    "extrapolation_ok",
    "cost_test",
    "separates_above",
    "separates_below",
    "figure",
];
/// The object of the parameters' 2σ widths (keyed by parameter name): finite and ≥ 0, no
/// band check.
const WIDTHS: &str = "uncertainty_2sigma";
/// Band factor.
const BAND: f64 = 1e6;

/// Checks one number `x` named `key` against the band `[w_lo, w_hi]` (rad/s).
fn check_number(key: &str, x: f64, w_lo: f64, w_hi: f64, out: &mut Vec<String>) {
    if !x.is_finite() {
        out.push(format!("{key} = {x} is not finite"));
        return;
    }
    if key == WIDTHS {
        if x < 0.0 {
            out.push(format!("a 2σ width {x} is negative"));
        }
        return;
    }
    let inside = |w: f64| w > w_lo / BAND && w < w_hi * BAND;
    if FREQ.contains(&key) && !inside(x) {
        out.push(format!(
            "{key} = {x} rad/s is beyond 1e6× the band {w_lo}…{w_hi}"
        ));
    }
    if key == "tau_s" && x > BAND / w_lo {
        out.push(format!(
            "tau_s = {x} s is beyond 1e6× the band's longest time constant"
        ));
    }
    if key == "t_s" && !inside(std::f64::consts::TAU / x) {
        out.push(format!("t_s = {x} s: fs beyond 1e6× the band"));
    }
    // A time constant is not a frequency: no other check.
    let _ = TIME;
}

/// Walks a JSON value: numbers finite and in band by their key, `null` only where a value
/// may be absent (serde writes a NaN or an infinity as `null`).  Returns what is wrong.
pub fn scan_json(v: &Value, w_lo: f64, w_hi: f64) -> Vec<String> {
    fn walk(v: &Value, key: &str, path: &str, w: (f64, f64), out: &mut Vec<String>) {
        match v {
            Value::Null if !MAY_BE_NULL.contains(&key) => {
                out.push(format!("{path} is null (a non-finite number?)"))
            }
            Value::Number(n) => match n.as_f64() {
                Some(x) => check_number(key, x, w.0, w.1, out),
                None => out.push(format!("{path} = {n} is not a number")),
            },
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, key, &format!("{path}[{i}]"), w, out);
                }
            }
            Value::Object(o) => {
                for (k, x) in o {
                    // A parameter's 2σ width is not a frequency (a sharp mode's ω_n may be
                    // known to 1e-3 rad/s): its entries keep the parent's key.
                    let key = if key == WIDTHS { WIDTHS } else { k.as_str() };
                    walk(x, key, &format!("{path}.{k}"), w, out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, "", "", (w_lo, w_hi), &mut out);
    out
}

/// Parses a printed token as a number (surrounding punctuation removed).
fn number(tok: &str) -> Option<f64> {
    let t = tok.trim_matches(|c: char| "()[],;:=+".contains(c) || c == '×');
    let t = t.strip_suffix('%').unwrap_or(t);
    if t.is_empty()
        || !t
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_digit() || c == '-')
    {
        return None;
    }
    t.parse::<f64>().ok()
}

/// Scans printed text: no `inf` or `NaN` printed as a number, every number followed by
/// `rad/s` or `Hz` within 1e6× of the band, every percentage below 1e6 %.
pub fn scan_text(text: &str, w_lo: f64, w_hi: f64) -> Vec<String> {
    let mut out = Vec::new();
    let toks: Vec<&str> = text.split_whitespace().collect();
    let inside = |w: f64| w > w_lo / BAND && w < w_hi * BAND;
    for (i, tok) in toks.iter().enumerate() {
        let bare = tok.trim_matches(|c: char| !c.is_alphanumeric() && c != '-' && c != '+');
        let lower = bare.to_ascii_lowercase();
        if ["inf", "-inf", "+inf", "nan", "infinity"].contains(&lower.as_str()) {
            out.push(format!("non-finite number printed: {tok:?}"));
        }
        let Some(x) = number(tok) else { continue };
        if !x.is_finite() {
            out.push(format!("non-finite number printed: {tok:?}"));
            continue;
        }
        let next = toks.get(i + 1).copied().unwrap_or("");
        let unit = next.trim_matches(|c: char| "()[],;:".contains(c));
        if unit == "rad/s" && !inside(x) {
            out.push(format!("{x} rad/s beyond 1e6× the band"));
        }
        if unit == "Hz" && !inside(std::f64::consts::TAU * x) {
            out.push(format!("{x} Hz beyond 1e6× the band"));
        }
        if (tok.ends_with('%') || next.starts_with('%')) && x.abs() >= 1e6 {
            out.push(format!("absurd percentage {tok} {next}"));
        }
    }
    out
}
