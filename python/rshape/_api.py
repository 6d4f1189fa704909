"""The pipeline's calls with typed results: check, fit, stability, synthesize, compare,
diagnose. The numerics are the Rust library's (``rshape._rshape``)."""

from __future__ import annotations

import enum
import json
import os
from typing import Any, Iterable, Optional, Sequence, Tuple, Union

import numpy as np

from . import _rshape as _core
from ._record import Record
from ._rshape import Config, Envelope, Frf, InputError

PathLike = Union[str, "os.PathLike[str]"]


def _config(config: Union[Config, PathLike]) -> Config:
    """A Config, or a path to load one from."""
    if isinstance(config, Config):
        return config
    if isinstance(config, (str, os.PathLike)):
        return Config.load(os.fspath(config))
    raise InputError(f"config: expected rshape.Config or a path, got {type(config).__name__}")


def _coeffs(v: Any, what: str) -> list:
    a = np.atleast_1d(np.asarray(v, dtype=float)).ravel()
    if a.size == 0:
        raise InputError(f"{what}: empty coefficient list")
    return [float(x) for x in a]


def _tf(r: Any, what: str = "r") -> Tuple[list, list]:
    """(num, den) of a bound given as a Fit, (num, den), a SISO control.TransferFunction,
    a Config (its [r]) or any object with .num and .den."""
    if isinstance(r, Fit):
        return list(r.num), list(r.den)
    if isinstance(r, Config):
        if r.r is None:
            raise InputError(f"{r.path}: no r to check: add an [r] table with num and den, or give r")
        return list(r.r[0]), list(r.r[1])
    if isinstance(r, (tuple, list)) and len(r) == 2:
        return _coeffs(r[0], f"{what} numerator"), _coeffs(r[1], f"{what} denominator")
    num, den = getattr(r, "num", None), getattr(r, "den", None)
    if num is not None and den is not None:
        # python-control keeps SISO coefficients as num[0][0]; ndarrays as given
        if hasattr(r, "ninputs") and (r.ninputs, r.noutputs) != (1, 1):
            raise InputError(f"{what}: a bound r is SISO; got a {r.noutputs}x{r.ninputs} system")
        while isinstance(num, (list, tuple)) and len(num) == 1 and isinstance(num[0], (list, tuple, np.ndarray)):
            num = num[0]
        while isinstance(den, (list, tuple)) and len(den) == 1 and isinstance(den[0], (list, tuple, np.ndarray)):
            den = den[0]
        if isinstance(num, np.ndarray) and num.dtype == object:
            num = num.ravel()[0]
        if isinstance(den, np.ndarray) and den.dtype == object:
            den = den.ravel()[0]
        return _coeffs(num, f"{what} numerator"), _coeffs(den, f"{what} denominator")
    raise InputError(
        f"{what}: give a Fit, (num, den), a control.TransferFunction or a Config with [r]; got {type(r).__name__}"
    )


class Verdict(enum.Enum):
    """The verdict on a bound r against an envelope."""

    CONSISTENT = "consistent"
    """|r| > r_min and A1 holds at every datum: r explains the data."""
    INCONSISTENT = "inconsistent"
    """|r| <= r_min at some datum."""
    NOT_ADMISSIBLE = "not_admissible"
    """A1 fails (|r| >= sigma_min(M~)) at some datum: no verdict on consistency there."""

    def __str__(self) -> str:
        return self.value


class Check(Record):
    """The check of r against an envelope (``rshape check --json``): ``verdict`` (a
    :class:`Verdict`), ``consistent``, ``failing_omegas``, ``a1_violations``, ``rows``; the
    rows' columns as arrays: ``omega``, ``r_abs``, ``r_min``, ``ratio``, ``a1_limit``,
    ``a1_ok``, ``covers``."""

    def __init__(self, data: dict):
        super().__init__(data)
        object.__setattr__(self, "verdict", Verdict(data["verdict"]))
        rows = data.get("rows", [])
        for col in ("omega", "r_abs", "r_min", "ratio"):
            object.__setattr__(self, col, np.array([row[col] for row in rows], dtype=float))
        a1 = [row.get("a1_limit") for row in rows]
        object.__setattr__(self, "a1_limit", np.array([np.nan if v is None else v for v in a1], dtype=float))
        for col in ("a1_ok", "covers"):
            object.__setattr__(self, col, np.array([bool(row.get(col)) for row in rows], dtype=bool))


def check(r: Any, envelope: Envelope) -> Check:
    """Checks a bound ``r`` (a Fit, (num, den), a control.TransferFunction, or a Config whose
    [r] is checked) against ``envelope``. Raises NotAdmissible when r is not a unit of
    RH-infinity (stable, minimum phase, biproper)."""
    num, den = _tf(r)
    return Check.from_json(_core._check(num, den, envelope))


class Fit:
    """A certified fitted unit r(s) (the ``r.json`` of ``rshape fit``).

    ``num``, ``den`` (descending powers of s), ``zeros``, ``poles`` (complex), ``gain``,
    ``order``, ``certificate`` (a Record: ``passed``, ``worst_ratio``, ...), ``order_table``
    (list of Records for order="auto", else None), ``json`` (the r.json text)."""

    def __init__(self, handle: Any):
        self._handle = handle
        d = json.loads(handle.json)
        self._data = d
        self.num = np.asarray(d["num"], dtype=float)
        self.den = np.asarray(d["den"], dtype=float)
        self.zeros = np.asarray([complex(z["re"], z["im"]) for z in d.get("zeros", [])], dtype=complex)
        self.poles = np.asarray([complex(p["re"], p["im"]) for p in d.get("poles", [])], dtype=complex)
        self.gain = float(d["gain"])
        self.order = int(d["order"])
        self.certificate = Record(d["certificate"])
        table = d.get("order_table")
        self.order_table = None if table is None else [Record(row) for row in table]

    @property
    def json(self) -> str:
        """The r.json document (coefficients, zeros, poles, gain, certificate, order table)."""
        return json.dumps(self._data, indent=2)

    def to_dict(self) -> dict:
        return self._data

    def freqresp(self, omega: Any) -> np.ndarray:
        """r(j*omega), complex, at each frequency in rad/s."""
        w = np.atleast_1d(np.asarray(omega, dtype=float))
        return np.asarray(self._handle.freqresp([float(x) for x in w.ravel()])).reshape(w.shape)

    def to_control(self):
        """r as a python-control TransferFunction (needs ``pip install control``)."""
        try:
            import control
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Fit.to_control needs python-control: pip install control") from e
        return control.tf(list(self.num), list(self.den))

    def __repr__(self) -> str:
        return (
            f"rshape.Fit(order {self.order}, certificate "
            f"{'passed' if self.certificate.passed else 'FAILED'}, "
            f"worst |r|/r_min = {self.certificate.worst_ratio:.6g})"
        )


def fit(envelope: Envelope, order: Union[str, int] = "auto", max_order: int = 8) -> Fit:
    """The smallest certified stable, minimum-phase, biproper r(s) above ``envelope`` (the
    fit of ``rshape run``): ``order="auto"`` sweeps 0..max_order and picks the smallest good
    order; an int fixes it. Raises FitError when no certified r is found."""
    return Fit(_core._fit(envelope, order, max_order))


def _bounds(r: Any) -> list:
    """Labelled bounds for stability/synthesize: None, one r (labelled "fitted"), a dict
    label -> r, or a list of (label, r)."""
    if r is None:
        return []
    if isinstance(r, dict):
        items: Iterable = r.items()
    elif isinstance(r, list) and r and all(isinstance(x, tuple) and len(x) == 2 and isinstance(x[0], str) for x in r):
        items = r
    else:
        items = [("fitted", r)]
    out = []
    for label, b in items:
        num, den = _tf(b, f"the {label} r")
        out.append((str(label), num, den))
    return out


class Stability(Record):
    """Theorem 1 for a controller (``rshape stability --json``): ``internally_stable``,
    ``closed_loop_poles``, ``b_gk``, ``t_norm``, ``margins`` (one per bound: ``label``,
    ``alpha`` (alpha*), ``omega``, ``alpha_grid``, ``alpha_lower``, ``verdict``, ``robust``),
    plus ``robust`` (every bound proven) and ``text`` (what the CLI prints)."""

    def __init__(self, data: dict, text: str = "", robust: Optional[bool] = None):
        super().__init__(data)
        object.__setattr__(self, "text", text)
        if robust is None:
            robust = bool(data.get("internally_stable")) and all(m["robust"] for m in data.get("margins", []))
        object.__setattr__(self, "robust", robust)

    def margin(self, label: str) -> Record:
        """The margin row of the bound ``label`` (``configured``, ``fitted``, …)."""
        for m in self.margins:
            if m.label == label:
                return m
        raise KeyError(label)


def _controller_args(controller: Any) -> dict:
    if isinstance(controller, (str, os.PathLike)):
        return {"path": os.fspath(controller)}
    if isinstance(controller, Synthesis):
        return {"abcd": controller._abcd}
    if isinstance(controller, (tuple, list)) and len(controller) == 4:
        mats = [np.atleast_2d(np.asarray(x, dtype=float)) for x in controller]
        return {"abcd": tuple(m.tolist() for m in mats)}
    if hasattr(controller, "A") and hasattr(controller, "D"):
        a = np.asarray(controller.A, dtype=float)
        return {"abcd": tuple(np.asarray(m, dtype=float).reshape(s).tolist() for m, s in (
            (controller.A, a.shape),
            (controller.B, (a.shape[0], np.asarray(controller.D).shape[1])),
            (controller.C, (np.asarray(controller.D).shape[0], a.shape[0])),
            (controller.D, np.asarray(controller.D).shape),
        ))}
    if hasattr(controller, "num") and hasattr(controller, "den"):
        try:
            import control
        except ImportError as e:  # pragma: no cover
            raise ImportError("a control.TransferFunction controller needs python-control") from e
        return _controller_args(control.ss(controller))
    raise InputError(
        "controller: give a controller TOML file, a Synthesis, a control.StateSpace/TransferFunction or (A, B, C, D)"
    )


def stability(config: Union[Config, PathLike], controller: Any, r: Any = None,
              feedback: str = "negative", data: Optional[PathLike] = None) -> Stability:
    """Theorem 1: is the loop of ``controller`` (u = -K y; ``feedback="positive"`` for
    u = +K y) robustly stable for the config's [r] ("configured") and ``r`` (a Fit or (num,
    den), labelled "fitted"; or a dict label -> r)? Same numbers as ``rshape stability``."""
    cfg = _config(config)
    kw = _controller_args(controller)
    js, text, robust = _core._stability(cfg, _bounds(r), feedback=feedback,
                                        data=None if data is None else os.fspath(data), **kw)
    return Stability(json.loads(js), text, robust)


class Synthesis(Record):
    """A synthesized controller (``synthesis.json`` of ``rshape synthesize``): ``method``,
    ``b_opt``, ``gamma`` (the controller's: H∞'s with ``gamma_opt``, or Glover–McFarlane's
    with ``gamma_min``), ``glover_mcfarlane`` (its ``b_opt``, ``gamma_min``, ``gamma``),
    ``controller_order``, ``controller_poles``,
    ``bounds`` (alpha per bound), ``robust``, ``notes``; the controller ``A``, ``B``, ``C``,
    ``D`` (u = -K y), ``controller_toml``, ``stability`` (the Theorem 1 proof), ``text``."""

    def __init__(self, data: dict, report: dict, toml: str, abcd: tuple, text: str):
        super().__init__(data)
        object.__setattr__(self, "_abcd", abcd)
        for name, m in zip("ABCD", abcd):
            object.__setattr__(self, name, np.asarray(m, dtype=float).reshape(len(m), -1) if m else np.zeros((0, 0)))
        n = len(abcd[0])
        p = self.D.shape[1]
        m = self.D.shape[0]
        object.__setattr__(self, "B", self.B.reshape(n, p))
        object.__setattr__(self, "C", self.C.reshape(m, n))
        object.__setattr__(self, "controller_toml", toml)
        object.__setattr__(self, "stability", Stability(report))
        object.__setattr__(self, "text", text)

    def to_control(self):
        """The controller K (u = -K y) as a python-control StateSpace."""
        try:
            import control
        except ImportError as e:  # pragma: no cover
            raise ImportError("Synthesis.to_control needs python-control: pip install control") from e
        return control.ss(self.A, self.B, self.C, self.D)


def synthesize(config: Union[Config, PathLike], method: str = "gm", r: Any = None,
               gamma_factor: float = 1.1, reduce: Optional[int] = None,
               weights: Optional[PathLike] = None, data: Optional[PathLike] = None) -> Synthesis:
    """The Glover-McFarlane controller (``method="gm"``) or the H-infinity optimum with a
    frequency-dependent r as weight (``"hinf"``) of the config's plant, proved by Theorem 1
    for the config's [r] and ``r`` (as "fitted"). Same numbers as ``rshape synthesize``."""
    cfg = _config(config)
    s, rep, toml, abcd, text = _core._synthesize(
        cfg, _bounds(r), method=method, gamma_factor=gamma_factor, reduce=reduce,
        weights=None if weights is None else os.fspath(weights),
        data=None if data is None else os.fspath(data))
    return Synthesis(json.loads(s), json.loads(rep), toml, abcd, text)


class Comparison(Record):
    """``rshape compare --json``: verdict, misfit per frequency (``rows``), failing
    ``bands``, error measures."""


def compare(config: Union[Config, PathLike], frf: Optional[Frf] = None,
            channel: Optional[Tuple[int, int]] = None,
            noise_radius: Optional[float] = None) -> Comparison:
    """The model against the data (the config's file, or ``frf``)."""
    return Comparison.from_json(_core._compare(_config(config), frf, channel, noise_radius))


class Diagnosis(Record):
    """``rshape diagnose --json``: ``candidates`` (ranked), ``chosen`` set, ``changes``,
    ``peaks`` …; :meth:`apply` gives the revised config text."""

    def __init__(self, handle: Any):
        super().__init__(json.loads(handle.json))
        object.__setattr__(self, "_handle", handle)
        object.__setattr__(self, "converted", handle.converted)

    def apply(self, what: Union[str, int] = "chosen", force: bool = False,
              write: Optional[PathLike] = None) -> str:
        """The revised config's TOML text with the chosen effect set (``"chosen"``) or the
        K-th ranked candidate (``what=K``, 1-based; a rejected one only with force=True), as
        ``rshape diagnose --apply … --write FILE`` writes it. With ``write=FILE`` the file is
        written; without, the text is for a file beside the diagnosed config (its data
        paths are relative to that folder)."""
        text, _label = self._handle.apply(what, force, None if write is None else os.fspath(write))
        return text


def diagnose(config: Union[Config, PathLike], frf: Optional[Frf] = None,
             channel: Optional[Tuple[int, int]] = None, noise_radius: Optional[float] = None,
             max_effects: int = 3, beam: int = 3,
             band: Optional[Tuple[float, float]] = None,
             allow_mains: bool = False,
             exclude: Optional[Sequence[Tuple[float, float]]] = None) -> Diagnosis:
    """Which physical effects the model misses (the search of ``rshape diagnose``);
    ``band=(fmin, fmax)`` in Hz restricts the data; ``exclude=[(fmin, fmax), ...]`` in Hz
    leaves ranges out (``--exclude``: a mains line, a dropout); ``allow_mains=True`` lets a
    mode at 50/60 Hz or a harmonic pass (``--allow-mains``)."""
    ranges = None if exclude is None else [(float(a), float(b)) for a, b in exclude]
    return Diagnosis(_core._diagnose(_config(config), frf, channel, noise_radius,
                                     max_effects, beam, band, allow_mains, ranges))
