//! A controller `K` read from a TOML file with a `[controller]` table ([`Controller`]).

use super::config::TfEntry;
use super::plant::PlantSection;
use crate::error::{Error, Result};
use crate::system::StateSpace;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Sign convention of the loop.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Feedback {
    /// `u = −K·y`, loop `(I + GK)⁻¹`.
    #[default]
    Negative,
    /// `u = +K·y`, loop `(I − GK)⁻¹` (the convention of Boulet & Francis, Theorem 1).
    Positive,
}

/// The `[controller]` table.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSection {
    /// Transfer-function matrix (plant inputs × plant outputs).
    #[serde(default)]
    pub tf: Option<Vec<Vec<TfEntry>>>,
    /// State matrix, rows.
    #[serde(default)]
    pub a: Option<Vec<Vec<f64>>>,
    /// Input matrix, rows.
    #[serde(default)]
    pub b: Option<Vec<Vec<f64>>>,
    /// Output matrix, rows.
    #[serde(default)]
    pub c: Option<Vec<Vec<f64>>>,
    /// Feedthrough, rows.
    #[serde(default)]
    pub d: Option<Vec<Vec<f64>>>,
    /// A JSON state-space file, relative to the controller file.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// `"negative"` (default) or `"positive"`.
    #[serde(default)]
    pub feedback: Feedback,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ControllerFile {
    controller: ControllerSection,
}

/// A loaded controller, read from a TOML file with a `[controller]` table in the same three
/// forms as `[plant]` (a transfer-function matrix, inline `a`, `b`, `c`, `d`, or a JSON
/// state-space file):
///
/// ```toml
/// [controller]
/// tf = [[{ num = [2, 1], den = [1, 10] }]]   # m × p: plant inputs × plant outputs
/// feedback = "negative"                       # u = −K·y (default); "positive": u = +K·y
/// ```
///
/// The type is general: any consumer that needs `K` as a state-space system (the
/// robust-stability test, closed-loop data) can use it.
#[derive(Debug, Clone)]
pub struct Controller {
    /// The file it came from.
    pub path: PathBuf,
    /// `K` as written.
    pub k: StateSpace,
    /// The loop sign.
    pub feedback: Feedback,
}

impl Controller {
    /// `K` for the loop `u = −K·y` (the sign flipped for positive feedback).
    pub fn negative_feedback_gain(&self) -> StateSpace {
        match self.feedback {
            Feedback::Negative => self.k.clone(),
            Feedback::Positive => StateSpace {
                a: self.k.a.clone(),
                b: self.k.b.clone(),
                c: -&self.k.c,
                d: -&self.k.d,
            },
        }
    }

    /// Reads a controller file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::util::read_text_file(path)?;
        let err = |msg: String| Error::Config {
            path: path.to_path_buf(),
            msg,
        };
        let raw: ControllerFile = toml::from_str(&text).map_err(|e| {
            let line = e
                .span()
                .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let msg = e.message().replace('\n', " ");
            err(match line {
                Some(l) => format!("line {l}: {msg}"),
                None => msg,
            })
        })?;
        Self::from_section(&raw.controller, path)
    }

    /// Builds from a `[controller]` table; `path` resolves `file` and names errors.
    pub fn from_section(c: &ControllerSection, path: &Path) -> Result<Self> {
        let as_plant = PlantSection {
            tf: c.tf.clone(),
            a: c.a.clone(),
            b: c.b.clone(),
            c: c.c.clone(),
            d: c.d.clone(),
            file: c.file.clone(),
            reduce_order: None,
        };
        let k = as_plant
            .state_space(path.parent().unwrap_or(Path::new(".")))
            .map_err(|m| Error::Config {
                path: path.to_path_buf(),
                msg: m.replace("[plant]", "[controller]"),
            })?;
        Ok(Self {
            path: path.to_path_buf(),
            k,
            feedback: c.feedback,
        })
    }
}
