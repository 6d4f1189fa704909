//! Settings validation shared by every settings type of the library.
//!
//! Naming rule: a settings type is `<Concept>Settings` (`FitSettings`, `MuSettings`,
//! `BisectionSettings`, `VBisectionSettings`, `SearchSettings`, `BatchSettings`,
//! `SynthesisSettings`), its `Default` gives the documented defaults (each field's doc says
//! its default), and its `validate()` returns an [`InvalidSetting`] naming the first field out
//! of range, its value and the range it must be in.

/// A settings field out of its range: `FitSettings.margin = -1: must be a finite number ≥ 0`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{settings}.{field} = {value}: {requirement}")]
pub struct InvalidSetting {
    /// The settings type (`FitSettings`).
    pub settings: &'static str,
    /// The field (`margin`).
    pub field: &'static str,
    /// The value given, formatted.
    pub value: String,
    /// The range it must be in, in words.
    pub requirement: &'static str,
}

/// Checks the fields of one settings value, in order; the first failure is kept.
#[derive(Debug)]
pub(crate) struct Checker {
    settings: &'static str,
    first: Option<InvalidSetting>,
}

impl Checker {
    /// Starts the checks of the settings type named `settings`.
    pub fn new(settings: &'static str) -> Self {
        Self {
            settings,
            first: None,
        }
    }

    /// Requires `ok`; otherwise records `field = value: requirement`.
    pub fn require(
        mut self,
        field: &'static str,
        value: impl std::fmt::Display,
        ok: bool,
        requirement: &'static str,
    ) -> Self {
        if !ok && self.first.is_none() {
            self.first = Some(InvalidSetting {
                settings: self.settings,
                field,
                value: value.to_string(),
                requirement,
            });
        }
        self
    }

    /// `x` finite and `> 0`.
    pub fn positive(self, field: &'static str, x: f64) -> Self {
        self.require(
            field,
            x,
            x.is_finite() && x > 0.0,
            "must be a finite number > 0",
        )
    }

    /// `x` finite and `≥ 0`.
    pub fn non_negative(self, field: &'static str, x: f64) -> Self {
        self.require(
            field,
            x,
            x.is_finite() && x >= 0.0,
            "must be a finite number ≥ 0",
        )
    }

    /// `0 < x < 1`.
    pub fn fraction(self, field: &'static str, x: f64) -> Self {
        self.require(field, x, x > 0.0 && x < 1.0, "must be in (0, 1)")
    }

    /// An integer `≥ min`.
    pub fn at_least(
        self,
        field: &'static str,
        n: usize,
        min: usize,
        requirement: &'static str,
    ) -> Self {
        self.require(field, n, n >= min, requirement)
    }

    /// The first failure, if any.
    pub fn finish(self) -> Result<(), InvalidSetting> {
        self.first.map_or(Ok(()), Err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_bad_field_is_named_with_its_value_and_range() {
        let e = Checker::new("S")
            .positive("a", 1.0)
            .fraction("b", 1.5)
            .non_negative("c", -1.0)
            .finish()
            .unwrap_err();
        assert_eq!(e.to_string(), "S.b = 1.5: must be in (0, 1)");
        assert!(Checker::new("S").positive("a", f64::NAN).finish().is_err());
        assert!(Checker::new("S").non_negative("a", 0.0).finish().is_ok());
        assert!(Checker::new("S")
            .at_least("n", 0, 1, "must be ≥ 1")
            .finish()
            .is_err());
    }
}
