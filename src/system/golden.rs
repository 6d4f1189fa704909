//! Golden-section search for a local minimum of a unimodal function on an interval.
//!
//! Used where a sampled extremum is polished to its last digits: the certificate's grid
//! minimum of `|r|/r_min`, the attained minimum between two data, and the peak of `σ_max`
//! in the H∞ iteration. None of them relies on it for a guarantee.

/// Runs `iters` golden-section steps on `[a, b]` and returns `(x, f(x))`, the better of the
/// two interior points at the end. `f` is assumed unimodal on `[a, b]`; otherwise a local
/// minimum is returned.
pub fn golden_section_min(
    f: impl Fn(f64) -> f64,
    mut a: f64,
    mut b: f64,
    iters: usize,
) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iters {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    if fc < fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_vertex_of_a_parabola() {
        let (x, fx) = golden_section_min(|x| (x - 0.3).powi(2) + 2.0, -1.0, 2.0, 80);
        assert!((x - 0.3).abs() < 1e-7, "{x}");
        assert!((fx - 2.0).abs() < 1e-14);
    }
}
