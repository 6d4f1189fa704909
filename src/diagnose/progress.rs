//! What `diagnose` reports while it runs: its stages and the levels of its search, so that a
//! large model (hundreds of modes, minutes) is not silent.  The library only calls
//! [`DiagnoseOptions::progress`]; whoever passes it decides what to show (the CLI prints on
//! stderr from 100 modes on, rate-limited).

/// One report of a running `diagnose`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiagnoseProgress {
    /// A stage begins: `retune` (the configured parameters refit, with the configured
    /// model's screen beside it), `first level`, `holdout`, `backward elimination`,
    /// `final refit`, `ties`, `peak account`.
    Stage(&'static str),
    /// Level `depth` (1-based) of at most `max` of the beam search begins, with `nodes`
    /// effect sets to screen.
    Level {
        /// The level, 1-based.
        depth: usize,
        /// The most levels (`SearchSettings::max_effects`).
        max: usize,
        /// Effect sets screened at this level.
        nodes: usize,
    },
    /// Inside the `retune` stage (the configured parameters refit from a rough start, the
    /// longest silent part of a model of hundreds of modes): `what` is
    /// [`crate::diagnose::RETUNE_PLACING`] (`done` of `total` modes placed by their grid) or
    /// [`crate::diagnose::RETUNE_ITERATING`] (iteration `done` of the joint refit, at most
    /// `total`).
    Retune {
        /// Which count.
        what: &'static str,
        /// Done so far.
        done: usize,
        /// The most there will be.
        total: usize,
    },
    /// A joint refit of level `depth` finished: `done` of `total`.
    Refits {
        /// The level, 1-based.
        depth: usize,
        /// Refits finished so far at this level.
        done: usize,
        /// Refits of this level.
        total: usize,
    },
}

/// Receives each [`DiagnoseProgress`] (from several threads: the refits run in parallel).
pub type DiagnoseProgressFn<'a> = &'a (dyn Fn(DiagnoseProgress) + Sync);

/// What `diagnose` is told besides its settings, none of it changing the result: who hears
/// its progress.  `&DiagnoseOptions::default()` for none.
#[derive(Clone, Copy, Default)]
pub struct DiagnoseOptions<'a> {
    /// Hears of each stage and search level as it begins, and of each joint refit.
    pub progress: Option<DiagnoseProgressFn<'a>>,
}

impl DiagnoseOptions<'_> {
    /// Passes `p` on to [`Self::progress`], if any.
    pub(crate) fn tell(&self, p: DiagnoseProgress) {
        if let Some(f) = self.progress {
            f(p);
        }
    }
}
