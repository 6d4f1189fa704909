//! The one axis-range guard every figure goes through, and rshape's own axis coordinates.
//!
//! plotters' logarithmic coordinate computes its key points decade by decade from the raw
//! range: an axis up to `2e308 = ∞` (one datum of 1e308 padded by 2) or down to a subnormal
//! frequency made `run`, `stability`, `history` and `batch` hang or eat gigabytes.  Every
//! figure therefore builds its axes from [`LogAxis`], [`LinAxis`] or [`PhaseAxis`], whose
//! constructors make the range finite, positive where it must be, at most
//! [`MAX_DECADES`] wide, and whose key points are at most [`MAX_TICKS`] (bold) or
//! [`MAX_LIGHT`] (light grid lines) — whatever the data.  Values outside the range are drawn
//! at its edge by the figures (they clamp), never used to widen it.

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use std::ops::Range;

/// Smallest and largest value a log axis may reach: padding and tick arithmetic
/// (`10^d`, `v·2.5`) stay finite and normal inside.
pub const LOG_MIN: f64 = 1e-300;
/// See [`LOG_MIN`].
pub const LOG_MAX: f64 = 1e300;
/// Widest log axis, in decades (wider data are clamped to its edge).
pub const MAX_DECADES: f64 = 60.0;
/// Most labelled ticks on one axis.
pub const MAX_TICKS: usize = 12;
/// Most light grid lines on one axis.
pub const MAX_LIGHT: usize = 120;
/// Largest magnitude of a linear axis' ends.
pub const LIN_MAX: f64 = 1e300;

/// A guarded log range: `(lo, hi)` finite, inside `[LOG_MIN, LOG_MAX]`, at least a factor
/// 1.01 wide and at most [`MAX_DECADES`] decades (keeping the top, where the data of
/// interest usually are when one value underflows); `None` input ends give `(0.1, 10)`.
pub fn log_bounds(lo: f64, hi: f64) -> (f64, f64) {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    let (mut lo, mut hi) = match (ok(lo), ok(hi)) {
        (true, true) => (lo.min(hi), lo.max(hi)),
        (true, false) => (lo, lo * 100.0),
        (false, true) => (hi / 100.0, hi),
        (false, false) => (0.1, 10.0),
    };
    lo = lo.clamp(LOG_MIN, LOG_MAX);
    hi = hi.clamp(LOG_MIN, LOG_MAX);
    if hi < lo * 1.01 {
        let mid = (lo * hi).sqrt();
        lo = (mid / 10f64.sqrt()).max(LOG_MIN);
        hi = (mid * 10f64.sqrt()).min(LOG_MAX);
        if hi < lo * 1.01 {
            // At an end of the representable range: one decade inside it.
            if mid > 1.0 {
                lo = hi / 10.0;
            } else {
                hi = lo * 10.0;
            }
        }
    }
    if (hi / lo).log10() > MAX_DECADES {
        lo = hi / 10f64.powf(MAX_DECADES);
    }
    (lo, hi)
}

/// A guarded linear range: finite ends within `±LIN_MAX`, `hi > lo` by a representable
/// step (`(0, 1)` when nothing is finite).
pub fn lin_bounds(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = match (lo.is_finite(), hi.is_finite()) {
        (true, true) => (lo.min(hi), lo.max(hi)),
        (true, false) => (lo, lo + 1.0),
        (false, true) => (hi - 1.0, hi),
        (false, false) => (0.0, 1.0),
    };
    let (lo, hi) = (lo.clamp(-LIN_MAX, LIN_MAX), hi.clamp(-LIN_MAX, LIN_MAX));
    let min_step = 1e-9 * lo.abs().max(hi.abs()).max(1e-300);
    if hi - lo < min_step {
        let pad = (0.5 * lo.abs()).max(0.5);
        ((lo - pad).max(-LIN_MAX), (hi + pad).min(LIN_MAX))
    } else {
        (lo, hi)
    }
}

/// A log axis range covering the positive finite values, padded by the factor `pad` (and
/// at least a decade wide), through [`log_bounds`]; `None` without a positive finite value.
pub fn log_data_range<'a, I: IntoIterator<Item = &'a f64>>(
    values: I,
    pad: f64,
) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for &v in values {
        if v.is_finite() && v > 0.0 {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if hi == 0.0 {
        return None;
    }
    // Clamp before padding, so that the padding cannot overflow or underflow.
    let (lo, hi) = (lo.clamp(LOG_MIN, LOG_MAX), hi.clamp(LOG_MIN, LOG_MAX));
    let (mut lo, mut hi) = (lo / pad, hi * pad);
    if hi / lo < 10.0 {
        let mid = (lo * hi).sqrt();
        lo = mid / 10f64.sqrt();
        hi = mid * 10f64.sqrt();
    }
    Some(log_bounds(lo, hi))
}

/// Where `v` sits on `[lo, hi]` as a fraction (0 at `lo`, 1 at `hi`), for drawing at
/// sub-pixel precision; clamped to `[-1, 2]` and 0 for NaN, so no pixel is astronomically
/// far.
pub trait Fraction {
    /// The fraction of `v` along the axis.
    fn fraction(&self, v: f64) -> f64;
}

fn safe_fraction(t: f64) -> f64 {
    if t.is_nan() {
        0.0
    } else {
        t.clamp(-1.0, 2.0)
    }
}

fn map_pixels(t: f64, limit: (i32, i32)) -> i32 {
    (limit.0 as f64 + t * (limit.1 - limit.0) as f64).round() as i32
}

/// A logarithmic axis with rshape's ticks: decades (every k-th when there are many), or
/// 1-2-5 and finer sets on narrow ranges, never more than [`MAX_TICKS`].
#[derive(Debug, Clone)]
pub struct LogAxis {
    lo: f64,
    hi: f64,
    ln_lo: f64,
    ln_span: f64,
}

impl LogAxis {
    /// The axis over `[lo, hi]` after [`log_bounds`].
    pub fn new(lo: f64, hi: f64) -> Self {
        let (lo, hi) = log_bounds(lo, hi);
        Self {
            lo,
            hi,
            ln_lo: lo.ln(),
            ln_span: (hi / lo).ln(),
        }
    }

    /// The (guarded) ends.
    pub fn ends(&self) -> (f64, f64) {
        (self.lo, self.hi)
    }

    /// True when `v` lies on the axis.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.lo * (1.0 - 1e-12) && v <= self.hi * (1.0 + 1e-12)
    }

    /// The labelled ticks: at most `n` (and [`MAX_TICKS`]), at least two when the axis
    /// holds two "round" values.
    pub fn ticks(&self, n: usize) -> Vec<f64> {
        let n = n.clamp(2, MAX_TICKS);
        let (lo, hi) = (self.lo, self.hi);
        let d0 = lo.log10().floor() as i32;
        let d1 = hi.log10().ceil() as i32;
        let inside = |v: f64| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9);
        let decades = (d1 - d0).max(1) as usize;
        let with = |m: &[f64]| -> Vec<f64> {
            let mut t = Vec::new();
            for d in d0..=d1 {
                for &k in m {
                    let v = k * 10f64.powi(d);
                    if inside(v) {
                        t.push(v);
                    }
                }
            }
            t
        };
        // Wide: every k-th decade.
        let step = decades.div_ceil(n).max(1) as i32;
        let mut wide = Vec::new();
        let mut d = d0 + (d0.rem_euclid(step) != 0) as i32 * (step - d0.rem_euclid(step));
        while d <= d1 && wide.len() < n {
            let v = 10f64.powi(d);
            if inside(v) {
                wide.push(v);
            }
            d += step;
        }
        if wide.len() >= 3 {
            return wide;
        }
        for m in [
            &[1.0, 2.0, 5.0][..],
            &[1.0, 2.0, 3.0, 5.0],
            &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
        ] {
            let t = with(m);
            if t.len() >= 3 && t.len() <= n {
                return t;
            }
            if t.len() > n {
                break;
            }
        }
        // A decade or more: linear steps would leave the lower decades unlabelled (1, 2, 3, 4
        // on 0.02–4), so thin the 1-2-5 set to 1-3, else keep the decades.
        if hi / lo >= 10.0 {
            let t = with(&[1.0, 3.0]);
            if t.len() >= 3 && t.len() <= n {
                return t;
            }
            if wide.len() >= 2 {
                return wide;
            }
        }
        // Narrow: linear steps of 1-2-2.5-5 × 10ᵏ.
        let top = 10f64.powf((hi - lo).log10().floor());
        for e in [1.0, 0.1, 0.01] {
            for m in [5.0, 2.5, 2.0, 1.0] {
                let step = m * top * e;
                let mut t = Vec::new();
                let mut k = (lo / step).ceil();
                while k * step <= hi * (1.0 + 1e-9) && t.len() <= n {
                    t.push(k * step);
                    k += 1.0;
                }
                if t.len() >= 3 && t.len() <= n {
                    return t;
                }
            }
        }
        wide
    }

    /// Light grid lines: the mantissas 1…9 of every decade when that stays within `n`
    /// (and [`MAX_LIGHT`]), else the ticks.
    pub fn light(&self, n: usize) -> Vec<f64> {
        let n = n.min(MAX_LIGHT);
        let d0 = self.lo.log10().floor() as i32;
        let d1 = self.hi.log10().ceil() as i32;
        if ((d1 - d0).max(0) as usize) * 9 > n {
            return self.ticks(MAX_TICKS);
        }
        let mut t = Vec::new();
        for d in d0..=d1 {
            for k in 1..10 {
                let v = k as f64 * 10f64.powi(d);
                if self.contains(v) {
                    t.push(v);
                }
            }
        }
        t
    }
}

impl Fraction for LogAxis {
    fn fraction(&self, v: f64) -> f64 {
        if v <= 0.0 {
            return -1.0;
        }
        safe_fraction((v.ln() - self.ln_lo) / self.ln_span)
    }
}

impl Ranged for LogAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        map_pixels(self.fraction(*v), limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            Vec::new()
        } else if hint.weight().allow_light_points() {
            self.light(hint.max_num_points())
        } else {
            self.ticks(hint.max_num_points())
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// A linear axis over a guarded range ([`lin_bounds`]) with 1-2-5 ticks, at most
/// [`MAX_TICKS`].
#[derive(Debug, Clone)]
pub struct LinAxis {
    lo: f64,
    hi: f64,
}

impl LinAxis {
    /// The axis over `[lo, hi]` after [`lin_bounds`].
    pub fn new(lo: f64, hi: f64) -> Self {
        let (lo, hi) = lin_bounds(lo, hi);
        Self { lo, hi }
    }

    /// Ticks at multiples of a 1-2-5 step, at most `n`.
    pub fn ticks(&self, n: usize) -> Vec<f64> {
        let n = n.clamp(2, MAX_TICKS);
        let span = self.hi - self.lo;
        let mut step = 10f64.powf((span / n as f64).log10().floor());
        for m in [1.0, 2.0, 5.0, 10.0, 20.0, 50.0] {
            let s = step * m;
            if span / s <= n as f64 {
                step = s;
                break;
            }
        }
        multiples(self.lo, self.hi, step, n)
    }
}

/// The multiples of `step` in `[lo, hi]`, at most `n + 1`.
fn multiples(lo: f64, hi: f64, step: f64, n: usize) -> Vec<f64> {
    let mut t = Vec::new();
    if !(step > 0.0 && step.is_finite()) {
        return t;
    }
    let mut k = (lo / step - 1e-9).ceil();
    while k * step <= hi + 1e-9 * step && t.len() <= n {
        t.push(k * step + 0.0);
        k += 1.0;
    }
    t
}

impl Fraction for LinAxis {
    fn fraction(&self, v: f64) -> f64 {
        safe_fraction((v - self.lo) / (self.hi - self.lo))
    }
}

impl Ranged for LinAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        map_pixels(self.fraction(*v), limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            Vec::new()
        } else if hint.weight().allow_light_points() {
            self.ticks((2 * hint.bold_points()).max(2))
        } else {
            self.ticks(hint.max_num_points())
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// A phase axis (degrees): the range of the values widened to multiples of 90° (5° of air
/// at each end), its ticks at multiples of 90° (of 180°, 360°, … when there would be more
/// than [`MAX_TICKS`] − 3 of them).
#[derive(Debug, Clone)]
pub struct PhaseAxis {
    lo: f64,
    hi: f64,
    step: f64,
}

impl PhaseAxis {
    /// The axis over the finite values of `phases` (−180°…180° when there is none).
    pub fn covering<I: IntoIterator<Item = f64>>(phases: I) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in phases.into_iter().filter(|p| p.is_finite()) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if !lo.is_finite() {
            (lo, hi) = (-180.0, 180.0);
        }
        let (lo, hi) = (lo.max(-1e6), hi.min(1e6).max(lo.max(-1e6)));
        let lo = ((lo - 5.0) / 90.0).floor() * 90.0;
        let hi = (((hi + 5.0) / 90.0).ceil() * 90.0).max(lo + 90.0);
        let mut step = 90.0;
        while (hi - lo) / step > (MAX_TICKS - 3) as f64 {
            step *= 2.0;
        }
        Self { lo, hi, step }
    }

    /// The ends (multiples of 90°).
    pub fn ends(&self) -> (f64, f64) {
        (self.lo, self.hi)
    }

    /// The ticks (degrees): multiples of the step, itself a multiple of 90°.
    pub fn ticks(&self) -> Vec<f64> {
        multiples(self.lo, self.hi, self.step, MAX_TICKS)
    }

    /// Clamps `v` into the axis.
    pub fn clamp(&self, v: f64) -> f64 {
        if v.is_nan() {
            self.lo
        } else {
            v.clamp(self.lo, self.hi)
        }
    }
}

impl Fraction for PhaseAxis {
    fn fraction(&self, v: f64) -> f64 {
        safe_fraction((v - self.lo) / (self.hi - self.lo))
    }
}

impl Ranged for PhaseAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        map_pixels(self.fraction(*v), limit)
    }

    fn key_points<H: KeyPointHint>(&self, _hint: H) -> Vec<f64> {
        self.ticks()
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// Phase in degrees, unwrapped along the sequence (no jump larger than 180° between finite
/// neighbours), starting in (−180°, 180°]; NaN stays NaN.  The one phase convention of the
/// Bode figures (`run`'s `bode.svg` and `compare`'s overlay).
pub fn unwrap_deg(g: &[num_complex::Complex64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(g.len());
    for z in g {
        let p = z.arg().to_degrees();
        let v = match out.iter().rev().find(|v| v.is_finite()) {
            Some(prev) if p.is_finite() => p + 360.0 * ((prev - p) / 360.0).round(),
            _ => p,
        };
        out.push(v);
    }
    out
}

/// A phase tick label: `−90°`, `0°`, `180°`.
pub fn phase_tick(v: &f64) -> String {
    let v = v.round() + 0.0;
    if v < 0.0 {
        format!("−{}°", -v)
    } else {
        format!("{v}°")
    }
}

/// A log tick label: plain numbers from 0.01 to 99999 (`0.05`, `200`, `1200`), else `1e-3`,
/// `2e5`, `1e-300`.
pub fn log_label(v: &f64) -> String {
    let v: f64 = format!("{:.5e}", *v).parse().unwrap_or(*v);
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    if (0.01..1e5).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

#[cfg(test)]
mod tests;
