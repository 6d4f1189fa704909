"""rshape for Python: the smallest uncertainty bound r(s) consistent with measured
frequency-response data, on the same Rust core as the ``rshape`` command line.

The pipeline, numpy in and out, typed results::

    import rshape
    cfg = rshape.Config.load("configs/plant_first.toml")
    env = rshape.envelope(cfg)                 # per-datum smallest |r| (Theorems 2-4)
    chk = rshape.check(cfg, env)               # the configured r: Verdict.CONSISTENT, ...
    fit = rshape.fit(env, order="auto")        # smallest certified r(s) above env
    r = fit.to_control()                       # control.TransferFunction (python-control)

Errors raise :class:`InputError` (bad files, shapes, values), :class:`AssumptionError`,
:class:`NotAdmissible` (an r that is not a unit of RH-infinity) or :class:`FitError`, with
the one-line message the CLI prints; a bug raises :class:`InternalError`, never a crash.
"""

from __future__ import annotations

from ._rshape import (  # noqa: F401
    AssumptionError,
    Config,
    Envelope,
    FitError,
    Frf,
    InputError,
    InternalError,
    NotAdmissible,
    RshapeError,
    __version__,
    envelope,
    read_frf,
)
from ._api import (  # noqa: F401
    Check,
    Comparison,
    Diagnosis,
    Fit,
    Stability,
    Synthesis,
    Verdict,
    check,
    compare,
    diagnose,
    fit,
    stability,
    synthesize,
)
from ._batch import (  # noqa: F401
    BatchResult,
    Dataset,
    DatasetResult,
    batch,
    discover,
    run_dataset,
    summary_csv,
)

__all__ = [
    "AssumptionError", "BatchResult", "Check", "Comparison", "Config", "Dataset",
    "DatasetResult", "Diagnosis", "Envelope", "Fit", "FitError", "Frf", "InputError",
    "InternalError", "NotAdmissible", "RshapeError", "Stability", "Synthesis", "Verdict",
    "batch", "check", "compare", "diagnose", "discover", "envelope", "fit", "read_frf",
    "run_dataset", "stability", "summary_csv", "synthesize",
]
