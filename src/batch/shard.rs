//! `--shard K/N`: process every N-th dataset starting at K (0-based), so that a batch can
//! be split over the tasks of a cluster scheduler's array job (task K of N) and combined
//! afterwards with `rshape merge`.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Shard `k` of `n` (0 ≤ k < n).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, 0-based.
    pub k: usize,
    /// Number of shards.
    pub n: usize,
}

impl Shard {
    /// The whole batch.
    pub const ALL: Shard = Shard { k: 0, n: 1 };

    /// Parses `K/N`.
    pub fn parse(s: &str) -> Result<Self> {
        let bad = || Error::Argument {
            arg: format!("--shard `{s}`"),
            msg: "expected K/N with 0 ≤ K < N, e.g. 0/4 (K is 0-based, like $SLURM_ARRAY_TASK_ID)"
                .into(),
        };
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (k, n): (usize, usize) = (
            k.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if n == 0 || k >= n {
            return Err(bad());
        }
        Ok(Shard { k, n })
    }

    /// True when the dataset at `index` belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.n == self.k
    }

    /// The items of this shard, in order.
    pub fn select<T: Clone>(&self, items: &[T], index: impl Fn(&T) -> usize) -> Vec<T> {
        items
            .iter()
            .filter(|d| self.contains(index(d)))
            .cloned()
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::Shard;

    #[test]
    fn parse_and_select() {
        let s = Shard::parse("1/3").unwrap();
        let v: Vec<usize> = (0..8).collect();
        assert_eq!(s.select(&v, |x| *x), vec![1, 4, 7]);
        assert!(Shard::parse("3/3").is_err());
        assert!(Shard::parse("0/0").is_err());
        assert!(Shard::parse("x").is_err());
    }
}
