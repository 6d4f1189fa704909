//! Field-by-field validation of [`FitSettings`] (the naming rule of [`crate::settings`]).

use super::FitSettings;
use crate::settings::{Checker, InvalidSetting};

/// The highest order a fit accepts: the LP's basis and the root finding of `r` are
/// conditioned for this; beyond it a rational fit of an envelope is not meaningful.
pub const MAX_ORDER: usize = 20;

impl FitSettings {
    /// Checks every field against its documented range; the error names the first bad field.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        Checker::new("FitSettings")
            .require(
                "order",
                self.order,
                self.order <= MAX_ORDER,
                "must be at most 20",
            )
            .non_negative("margin", self.margin)
            .fraction("floor_rel", self.floor_rel)
            .at_least(
                "grid_per_decade",
                self.grid_per_decade,
                50,
                "must be at least 50 points per decade",
            )
            .non_negative("extend_decades", self.extend_decades)
            .require(
                "a1_backoff",
                self.a1_backoff,
                (0.0..1.0).contains(&self.a1_backoff),
                "must be in [0, 1)",
            )
            .fraction("bisection_tol", self.bisection_tol)
            .require(
                "area_slack",
                self.area_slack,
                self.area_slack.is_finite() && self.area_slack >= 1.0,
                "must be a finite number ≥ 1",
            )
            .fraction("axis_tol", self.axis_tol)
            .require(
                "max_solver_iter",
                self.max_solver_iter,
                self.max_solver_iter >= 1,
                "must be at least 1",
            )
            .at_least("root_iter_cap", self.root_iter_cap, 1, "must be at least 1")
            .at_least(
                "cert_per_decade",
                self.cert_per_decade,
                50,
                "must be at least 50 points per decade",
            )
            .non_negative("auto_tolerance", self.auto_tolerance)
            .require(
                "cut_rounds",
                self.cut_rounds,
                self.cut_rounds <= 10,
                "must be at most 10",
            )
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_each_bad_field_is_named() {
        assert_eq!(FitSettings::default().validate(), Ok(()));
        let bad: Vec<(&str, FitSettings)> = vec![
            (
                "margin",
                FitSettings {
                    margin: -0.1,
                    ..Default::default()
                },
            ),
            (
                "floor_rel",
                FitSettings {
                    floor_rel: 1.0,
                    ..Default::default()
                },
            ),
            (
                "grid_per_decade",
                FitSettings {
                    grid_per_decade: 10,
                    ..Default::default()
                },
            ),
            (
                "bisection_tol",
                FitSettings {
                    bisection_tol: 0.0,
                    ..Default::default()
                },
            ),
            (
                "axis_tol",
                FitSettings {
                    axis_tol: f64::NAN,
                    ..Default::default()
                },
            ),
            (
                "auto_tolerance",
                FitSettings {
                    auto_tolerance: -1.0,
                    ..Default::default()
                },
            ),
            (
                "area_slack",
                FitSettings {
                    area_slack: 0.5,
                    ..Default::default()
                },
            ),
            (
                "order",
                FitSettings {
                    order: 41,
                    ..Default::default()
                },
            ),
        ];
        for (field, s) in bad {
            let e = s.validate().unwrap_err();
            assert_eq!(e.field, field, "{e}");
            assert!(
                e.to_string()
                    .starts_with(&format!("FitSettings.{field} = ")),
                "{e}"
            );
        }
    }
}
