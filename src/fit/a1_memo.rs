//! A memo of the A1 limit for one fit (issue 38's profile step, docs/internals-fit-profile.md).

use super::A1Fn;
use std::cell::RefCell;
use std::collections::HashMap;

/// A memo of the A1 limit `ω ↦ σ_min(M̃(jω))` for one fit, keyed by the bits of `ω`.
///
/// The certificate evaluates the limit on the same dense grid and data for every candidate
/// of every order (ISS `stability --fit`: 113,681 calls at 3460 distinct frequencies, 18 % of
/// the fit's CPU; docs/internals-fit-profile.md).  The limit is a function of `ω` alone, so a
/// value computed once is returned for every later call at the same `ω`, to the bit: the fit
/// is unchanged, only the repeated evaluations go.  At most [`A1Memo::CAP`] values are kept
/// (beyond it the limit is evaluated as before).  Not `Sync`, like the [`A1Fn`] it wraps: one
/// fit's calls come from one thread.
pub(crate) struct A1Memo<'a> {
    f: Option<A1Fn<'a>>,
    table: RefCell<HashMap<u64, f64>>,
}

impl<'a> A1Memo<'a> {
    /// Values kept at most (a few MB).
    pub(crate) const CAP: usize = 1 << 17;

    /// A memo of `f` (none: nothing to remember).
    pub(crate) fn new(f: Option<A1Fn<'a>>) -> Self {
        Self {
            f,
            table: RefCell::new(HashMap::new()),
        }
    }

    /// `f(ω)`, from the memo when `ω` (to the bit) was asked before.  NaN without `f` (never
    /// asked then: [`Self::wrap`] gives no function; a NaN would fail every check).
    pub(crate) fn eval(&self, w: f64) -> f64 {
        let Some(f) = self.f else {
            return f64::NAN;
        };
        if let Some(v) = self.table.borrow().get(&w.to_bits()) {
            return *v;
        }
        let v = f(w);
        let mut t = self.table.borrow_mut();
        if t.len() < Self::CAP {
            t.insert(w.to_bits(), v);
        }
        v
    }

    /// `Some(memoized)` when the memo has a function, `None` otherwise: what the fit takes in
    /// place of the caller's `a1`.  `memoized` is `|w| self.eval(w)`, made by the caller
    /// (a closure cannot be returned as a `&dyn Fn` borrowed from `self`).
    pub(crate) fn wrap<'s>(&self, memoized: &'s dyn Fn(f64) -> f64) -> Option<A1Fn<'s>> {
        self.f.map(|_| memoized)
    }
}

#[cfg(test)]
mod tests {
    use super::A1Memo;
    use std::cell::Cell;

    /// The memo returns the function's own value to the bit (also for `-0.0` against `0.0`,
    /// NaN and a value computed beyond the cap), and calls the function once per distinct `ω`
    /// while below the cap.
    #[test]
    fn a1_memo_returns_the_functions_bits_once_per_frequency() {
        let calls = Cell::new(0usize);
        // Distinguishes ±0 and is not smooth, so a wrong key shows in the value.
        let f = |w: f64| {
            calls.set(calls.get() + 1);
            if w.to_bits() == (-0.0f64).to_bits() {
                -7.0
            } else {
                (w * 1e3).sin() / (1.0 + w * w) + w.to_bits() as f64 * 1e-30
            }
        };
        let memo = A1Memo::new(Some(&f));
        let memoized = |w: f64| memo.eval(w);
        let g = memo.wrap(&memoized).expect("a function");
        let ws: Vec<f64> = (0..500).map(|k| 1e-3 * 1.037f64.powi(k)).collect();
        for pass in 0..3 {
            for &w in &ws {
                assert_eq!(g(w).to_bits(), f(w).to_bits(), "pass {pass}, w = {w}");
            }
        }
        // Each pass: 500 direct calls; the memo's own calls only on the first pass.
        assert_eq!(calls.get(), 3 * 500 + 500);
        assert_eq!(g(0.0).to_bits(), f(0.0).to_bits());
        assert_eq!(g(-0.0), -7.0);
        assert!(g(f64::NAN).is_nan());
        assert!(A1Memo::new(None).wrap(&memoized).is_none());
        assert!(A1Memo::new(None).eval(1.0).is_nan());
    }

    /// Beyond [`A1Memo::CAP`] distinct frequencies the memo keeps no more, and every value
    /// is still the function's.
    #[test]
    fn a1_memo_beyond_its_cap_still_evaluates() {
        let calls = Cell::new(0usize);
        let f = |w: f64| {
            calls.set(calls.get() + 1);
            w.sqrt() + 1.0
        };
        let memo = A1Memo::new(Some(&f));
        let n = A1Memo::CAP + 1000;
        for k in 0..n {
            let w = k as f64;
            assert_eq!(memo.eval(w).to_bits(), (w.sqrt() + 1.0).to_bits());
        }
        assert_eq!(memo.table.borrow().len(), A1Memo::CAP);
        let before = calls.get();
        // Kept: no call; not kept: a call, the same value.
        assert_eq!(memo.eval(5.0).to_bits(), (5f64.sqrt() + 1.0).to_bits());
        assert_eq!(calls.get(), before);
        let w = (n - 1) as f64;
        assert_eq!(memo.eval(w).to_bits(), (w.sqrt() + 1.0).to_bits());
        assert_eq!(calls.get(), before + 1);
    }
}
