//! Loop-shaping weights (McFarlane & Glover 1990; Skogestad & Postlethwaite §9.4.2): the
//! plant is shaped, `G_s = W₂·G·W₁`, the robust controller `K∞` is synthesized for `G_s`,
//! and `K = W₁·K∞·W₂` is returned. Weights are diagonal, each entry a biproper transfer
//! function (a PI weight `(s + a)/s` for integral action is the common case):
//!
//! ```toml
//! [weights]
//! w1 = [{ num = [1, 2], den = [1, 0] }]   # plant inputs: one entry (repeated) or m entries
//! w2 = [1]                                 # plant outputs: one entry or p entries
//! ```

use crate::error::{Error, Result};
use crate::model::config::TfEntry;
use crate::system::{StateSpace, TfMatrix, TransferFunction};
use serde::Deserialize;
use std::path::Path;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct WeightsFile {
    weights: WeightsSection,
}

/// The `[weights]` table.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WeightsSection {
    /// Pre-weight `W₁` (at the plant inputs), diagonal entries.
    #[serde(default)]
    pub w1: Option<Vec<TfEntry>>,
    /// Post-weight `W₂` (at the plant outputs), diagonal entries.
    #[serde(default)]
    pub w2: Option<Vec<TfEntry>>,
}

/// Loaded weights as diagonal state-space systems.
#[derive(Debug, Clone)]
pub struct Weights {
    /// `W₁` (m × m).
    pub w1: StateSpace,
    /// `W₂` (p × p).
    pub w2: StateSpace,
}

fn diagonal(
    entries: Option<&[TfEntry]>,
    size: usize,
    name: &str,
    path: &Path,
) -> Result<StateSpace> {
    let bad = |msg: String| Error::Config {
        path: path.to_path_buf(),
        msg,
    };
    let tfs: Vec<TransferFunction> = match entries {
        None => vec![TransferFunction::gain(1.0); size],
        Some(list) => {
            if list.len() != 1 && list.len() != size {
                return Err(bad(format!(
                    "{name} has {} entries; give one (used on every channel) or {size}",
                    list.len()
                )));
            }
            let mut tfs = Vec::new();
            for (k, e) in list.iter().enumerate() {
                let tf = e.to_tf(&format!("{name} entry {}", k + 1)).map_err(bad)?;
                if !tf.is_biproper() {
                    return Err(bad(format!(
                        "{name} entry {} is not biproper (numerator and denominator of the same degree, nonzero at s = ∞): a shaping weight must be invertible at high frequency",
                        k + 1
                    )));
                }
                tfs.push(tf);
            }
            if tfs.len() == 1 {
                tfs = vec![tfs[0].clone(); size];
            }
            tfs
        }
    };
    Ok(StateSpace::from_tf_matrix(&TfMatrix::diagonal(tfs)))
}

impl Weights {
    /// Reads `[weights]` from `path` for a plant with `m` inputs and `p` outputs.
    pub fn load(path: &Path, m: usize, p: usize) -> Result<Self> {
        // The guarded reader of every input: a size cap, no FIFO or device (`/dev/zero`
        // grew past 4 GB, a FIFO blocked forever).
        let text = crate::util::read_text_file(path)?;
        let raw: WeightsFile = toml::from_str(&text).map_err(|e| Error::Config {
            path: path.to_path_buf(),
            msg: format!(
                "{}; expected a [weights] table with w1 = [...] and/or w2 = [...]",
                e.message().replace('\n', " ")
            ),
        })?;
        Ok(Self {
            w1: diagonal(raw.weights.w1.as_deref(), m, "w1", path)?,
            w2: diagonal(raw.weights.w2.as_deref(), p, "w2", path)?,
        })
    }

    /// The shaped plant `W₂·G·W₁`.
    pub fn shape(&self, g: &StateSpace) -> StateSpace {
        self.w2.series(&g.series(&self.w1))
    }

    /// The controller for the plant, `W₁·K∞·W₂`.
    pub fn controller(&self, k_inf: &StateSpace) -> StateSpace {
        self.w1.series(&k_inf.series(&self.w2))
    }
}
