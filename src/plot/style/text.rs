//! Titles and labels as text: a title shortened to its width, a text's estimated width, a
//! transfer function's short form.

/// Shortens `title` to fit `width` pixels in font `font`: the part after the last ` — `
/// (the configuration's name) loses whole words from its middle, replaced by `…`; then,
/// if still too wide, the title is cut at a word boundary.
pub fn fit_title(title: &str, width: f64, font: u32) -> String {
    // The SVG backend writes the size as font/1.24 px; 0.55 em a character is wider than the
    // digits and lower-case letters of common sans fonts.
    let fits = |t: &str| t.chars().count() as f64 * 0.55 * font as f64 / 1.24 <= width;
    if fits(title) {
        return title.to_string();
    }
    let (head, name) = match title.rsplit_once(" — ") {
        Some((h, n)) => (format!("{h} — "), n.to_string()),
        None => (String::new(), title.to_string()),
    };
    let words: Vec<&str> = name.split(' ').collect();
    // Drop words from the middle of the name, keeping its first and last words.
    for drop in 1..words.len().saturating_sub(1) {
        let keep = words.len() - drop;
        let front = keep.div_ceil(2);
        let back = keep - front;
        let t = format!(
            "{head}{} … {}",
            words[..front].join(" "),
            words[words.len() - back..].join(" ")
        );
        if back > 0 && fits(&t) {
            return t;
        }
    }
    // Cut at a word boundary.
    let mut out = String::new();
    for w in title.split(' ') {
        let next = if out.is_empty() {
            w.to_string()
        } else {
            format!("{out} {w}")
        };
        if !fits(&format!("{next} …")) {
            break;
        }
        out = next;
    }
    if out.is_empty() {
        title
            .chars()
            .take((width / (0.5 * font as f64)) as usize)
            .collect()
    } else {
        format!("{out} …")
    }
}

/// A short human form of a transfer function, e.g. `(1e-8 s + 0.3)/(s + 1)`, or
/// `order-n unit` when that would be too long for a legend.
pub fn tf_label(tf: &crate::system::TransferFunction) -> String {
    fn poly(c: &[f64]) -> String {
        let n = c.len();
        let terms: Vec<String> = c
            .iter()
            .enumerate()
            .filter(|(_, x)| **x != 0.0)
            .map(|(k, x)| {
                let p = n - 1 - k;
                let coef = if p > 0 && *x == 1.0 {
                    String::new()
                } else {
                    crate::report::fmt::fmt_g(*x)
                };
                match p {
                    0 => crate::report::fmt::fmt_g(*x),
                    1 => format!("{coef} s"),
                    _ => format!("{coef} s^{p}"),
                }
                .trim()
                .to_string()
            })
            .collect();
        if terms.is_empty() {
            "0".into()
        } else {
            terms.join(" + ").replace("+ -", "− ")
        }
    }
    let (num, den) = (poly(tf.num.coeffs()), poly(tf.den.coeffs()));
    let full = if den == "1" {
        num
    } else {
        format!("({num})/({den})")
    };
    if full.chars().count() > 48 {
        format!("order-{} unit", tf.den.degree())
    } else {
        full
    }
}

/// Estimated width in pixels of `text` in the sans-serif font of size `font`: the SVG backend
/// writes the size as `font/1.24` px, and 0.62 em per character of that is wider than the
/// digits and lower-case letters of common sans fonts.
pub fn text_width(text: &str, font: u32) -> f64 {
    text.chars().count() as f64 * 0.5 * font as f64
}
