//! Figures as SVG text, drawn with plotters' SVG backend (text is emitted as `<text>`
//! elements, so no system font is needed to make or to view them).
//!
//! Each function takes plain data and returns the SVG document as a `String`; the caller
//! writes it (atomically).  The figures are the analogues of the paper's:
//! - `r_vs_delta`: Fig. 3 and Fig. 8 side by side in spirit: `|r(jω)|` against the
//!   per-datum smallest consistent `|r|` (`‖Δᵢ‖` of eq. (8), or the Theorem 4 bisection);
//! - `bode`: the data (with noise-disk error bars, eq. (5)) against the nominal model,
//!   as in Fig. 7;
//! - `mu`: `μ_Γ` per datum with the line `μ = 1` (Fig. 8);
//! - `batch`: every dataset's envelope, the combined envelope and the one fitted `r`;
//! - `bode_overlay`: `compare`'s data against one or more models; both Bode figures are
//!   descriptions drawn by the one Bode drawer, `bode_chart` (chart pairs of magnitude over
//!   phase; the phase conventions, the layouts, the data and model marks);
//! - `history`: the error measures after each revision (`history`).
//!
//! Theorem numbers are those of Boulet & Francis 1998 (BF98 in docs/references.md);
//! Theorem 1 there is the robust stability theorem (Vidyasagar).
pub(crate) mod axis;
pub(crate) mod batch;
pub(crate) mod bode;
pub(crate) mod bode_chart;
pub(crate) mod bode_overlay;
pub(crate) mod fine;
pub(crate) mod history;
pub(crate) mod mu;
pub(crate) mod r_vs_delta;
pub(crate) mod stability;
pub(crate) mod style;
pub(crate) mod symbols;

pub use batch::{batch_svg, BatchFigureInput};
pub use bode::{bode_svg, BodeInput};
pub use mu::{mu_svg, mu_svg_with, MuInput};
pub use r_vs_delta::{r_vs_delta_svg, r_vs_delta_svg_with, RVsDeltaInput};
pub use stability::{stability_svg, StabilityInput};
pub use symbols::Symbols;
