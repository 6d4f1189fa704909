//! A memo of the last few LP solves (per thread): the level searches solve the very same LP
//! again more than once — a doubtful level of the polynomial candidate is solved without
//! iterative refinement, its solve short of `Solved` again with refinement, and then the
//! whole level again with refinement (`LevelLp::level`), whose first solves repeat the
//! retries just made; the thorough recheck of a stalled order repeats refined solves of
//! the fast route.  Clarabel is deterministic, so the same LP (compared exactly, every
//! coefficient and setting) gives the same answer: the memo returns it without a second
//! solve, and the fit is the same to the last bit (issue 38).

use super::problem::{Lp, LpOut};
use std::cell::RefCell;
use std::hash::{Hash, Hasher};

/// Entries kept.  Most repeats are within the last few solves of a level; 64 entries (8
/// before issue 38's seventh step) answer 63 more of the sweep's 17,672 Clarabel solves;
/// 477 exact repeats remain, on another thread or further back.
const ENTRIES: usize = 64;

/// Coefficients kept in all entries together, at most (16 MB): an LP with every row at
/// 2000 data and order 8 has about 110,000.
const MAX_COEFFS: usize = 2_000_000;

struct Entry {
    hash: u64,
    lp: Lp,
    max_iter: u32,
    refine: bool,
    out: LpOut,
}

thread_local! {
    static MEMO: RefCell<Vec<Entry>> = const { RefCell::new(Vec::new()) };
}

fn size(lp: &Lp) -> usize {
    lp.c.len() + (lp.ge.len() + lp.eq.len()) * (lp.n + 1)
}

fn hash(lp: &Lp, max_iter: u32, refine: bool) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (lp.n, max_iter, refine, lp.ge.len(), lp.eq.len()).hash(&mut h);
    let bits = |v: &[f64], h: &mut std::collections::hash_map::DefaultHasher| {
        v.iter().for_each(|x| x.to_bits().hash(h));
    };
    bits(&lp.c, &mut h);
    for (row, rhs) in lp.ge.iter().chain(&lp.eq) {
        bits(row, &mut h);
        rhs.to_bits().hash(&mut h);
    }
    h.finish()
}

/// The answer of `lp` with these settings, from the memo or from Clarabel; `true` when
/// Clarabel ran.
pub(super) fn solve(lp: &Lp, max_iter: u32, refine: bool) -> (LpOut, bool) {
    let key = hash(lp, max_iter, refine);
    let hit = MEMO.with(|m| {
        m.borrow()
            .iter()
            .find(|e| e.hash == key && e.max_iter == max_iter && e.refine == refine && e.lp == *lp)
            .map(|e| e.out.clone())
    });
    if let Some(out) = hit {
        return (out, false);
    }
    let out = lp.solve(max_iter, refine);
    MEMO.with(|m| {
        let mut m = m.borrow_mut();
        let new = size(lp);
        if new <= MAX_COEFFS {
            while m.len() >= ENTRIES
                || (!m.is_empty()
                    && m.iter().map(|e| size(&e.lp)).sum::<usize>() + new > MAX_COEFFS)
            {
                m.remove(0);
            }
            m.push(Entry {
                hash: key,
                lp: lp.clone(),
                max_iter,
                refine,
                out: out.clone(),
            });
        }
    });
    (out, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A repeat is answered by the memo with the same point; a different right-hand side or
    /// setting is solved again.
    #[test]
    fn repeat_is_answered_change_is_solved() {
        // min x + y  s.t.  x ≥ 1, y ≥ 2: (1, 2).
        let lp = Lp {
            n: 2,
            c: vec![1.0, 1.0],
            ge: vec![(vec![1.0, 0.0], 1.0), (vec![0.0, 1.0], 2.0)],
            eq: vec![],
        };
        let (a, ran_a) = solve(&lp, 50, false);
        let (b, ran_b) = solve(&lp, 50, false);
        assert!(ran_a && !ran_b);
        assert_eq!(a.x, b.x);
        assert!((a.x[0] - 1.0).abs() < 1e-6 && (a.x[1] - 2.0).abs() < 1e-6);
        let (_, ran_r) = solve(&lp, 50, true);
        assert!(ran_r, "another setting is another solve");
        let mut moved = lp.clone();
        moved.ge[1].1 = 3.0;
        let (c, ran_c) = solve(&moved, 50, false);
        assert!(ran_c);
        assert!((c.x[1] - 3.0).abs() < 1e-6, "{:?}", c.x);
    }
}
