"""Batch: many datasets on one model, as ``rshape batch`` runs them, in Rust threads
(:func:`batch`) or one dataset at a time for an engine of your own (:func:`run_dataset`,
then :func:`summary_csv`; see :mod:`rshape.dask`)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, List, Optional, Sequence, Union

from . import _rshape as _core
from ._api import Fit, _config
from ._record import Record
from ._rshape import Config, Envelope, InputError

PathLike = Union[str, "os.PathLike[str]"]


@dataclass(frozen=True)
class Dataset:
    """One dataset of a batch: its position in the full list (the output order), its
    unique name, its FRF file and an optional per-dataset noise radius (manifest)."""

    index: int
    name: str
    path: str
    noise_radius: Optional[float] = None

    def _tuple(self):
        return (int(self.index), str(self.name), os.fspath(self.path), self.noise_radius)


def discover(data_dir: Optional[PathLike] = None, manifest: Optional[PathLike] = None) -> List[Dataset]:
    """The datasets of a folder (every ``*.csv``, sorted by name) or a manifest CSV, named
    and numbered exactly as ``rshape batch --data-dir/--manifest`` does."""
    rows = _core._discover(None if data_dir is None else os.fspath(data_dir),
                           None if manifest is None else os.fspath(manifest))
    return [Dataset(i, n, os.fspath(p), r) for i, n, p, r in rows]


def _datasets(items: Union[PathLike, Sequence[Any]]) -> List[Dataset]:
    """Datasets from a folder, a list of Datasets or a list of file paths (named by stem)."""
    if isinstance(items, (str, os.PathLike)):
        if os.path.isdir(items):
            return discover(data_dir=items)
        raise InputError(f"{os.fspath(items)}: not a folder; give a folder, or a list of datasets or files")
    out: List[Dataset] = []
    for i, d in enumerate(items):
        if isinstance(d, Dataset):
            out.append(d)
        elif isinstance(d, (str, os.PathLike)):
            p = os.fspath(d)
            stem = os.path.splitext(os.path.basename(p))[0]
            out.append(Dataset(i, _core._safe_name(stem), p, None))
        else:
            raise InputError(f"datasets[{i}]: give a Dataset or a file path, got {type(d).__name__}")
    names = [d.name for d in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError(f"dataset names must be unique (they name output folders): {', '.join(dup)} repeated")
    return out


class DatasetResult(Record):
    """One dataset's outcome (``datasets/NAME/result.json`` of ``rshape batch``): ``index``,
    ``name``, ``path``, ``error`` (None on success), ``n_data``, ``max_r_min``,
    ``consistent``, ``verdict``, ``failing_omegas``, ``warnings``; plus ``ok``, the
    ``envelope`` (None on failure) and ``row`` (its summary.csv row, exact)."""

    def __init__(self, data: dict, envelope: Optional[Envelope], row: tuple):
        super().__init__(data)
        object.__setattr__(self, "envelope", envelope)
        object.__setattr__(self, "row", tuple(row))
        object.__setattr__(self, "ok", data.get("error") is None)

    def __reduce__(self):
        # Envelopes are rebuilt from their arrays on the other side (Dask results).
        env = self.envelope
        arrays = None if env is None else (list(env.omega), list(env.r_min),
                                           None if env.a1_limit is None else list(env.a1_limit))
        return (_rebuild_result, (self.to_dict(), arrays, self.row))


def _rebuild_result(data, arrays, row):
    env = None if arrays is None else Envelope(*arrays)
    return DatasetResult(data, env, row)


def run_dataset(config: Union[Config, PathLike], dataset: Union[Dataset, PathLike],
                noise_radius: Optional[float] = None) -> DatasetResult:
    """One dataset as ``rshape batch`` processes it: the envelope and the check of the
    configured r. A bad dataset gives a failed result (``ok`` False, ``error`` set), not an
    exception, as in the CLI's batch."""
    d = dataset if isinstance(dataset, Dataset) else _datasets([dataset])[0]
    js, env, row = _core._run_dataset(_config(config), d._tuple(), noise_radius)
    return DatasetResult(Record.from_json(js).to_dict(), env, row)


def summary_csv(results: Sequence[DatasetResult]) -> str:
    """``summary.csv`` of results (sorted by index), byte for byte as ``rshape batch``
    writes it."""
    rows = sorted((r.row for r in results), key=lambda row: row[0])
    return _core._summary_csv(rows)


class BatchResult:
    """A batch: ``results`` (one :class:`DatasetResult` per dataset, in order),
    ``summary_csv`` (the text of summary.csv), ``combined`` (the pointwise maximum of the
    envelopes, or None), ``fit`` (one r above it, or None) and ``fit_error``."""

    def __init__(self, results, summary, combined, fit, fit_error):
        self.results: List[DatasetResult] = results
        self.summary_csv: str = summary
        self.combined: Optional[Envelope] = combined
        self.fit: Optional[Fit] = fit
        self.fit_error: Optional[str] = fit_error

    @property
    def n_failed(self) -> int:
        return sum(not r.ok for r in self.results)

    def __repr__(self) -> str:
        return (f"rshape.BatchResult({len(self.results)} datasets, {self.n_failed} failed, "
                f"fit: {self.fit if self.fit is not None else self.fit_error})")


def batch(config: Union[Config, PathLike], datasets: Union[PathLike, Sequence[Any]],
          out: Optional[PathLike] = None, order: Union[str, int] = "auto",
          noise_radius: Optional[float] = None, jobs: Optional[int] = None,
          max_order: int = 8) -> BatchResult:
    """``rshape batch`` on a list of datasets (Datasets, files, or a folder): per dataset
    the envelope and the check of the configured r, in parallel Rust threads (``jobs``,
    default all cores); the combined envelope and one r fitted above it. With ``out``,
    writes every file the CLI writes there (summary.csv, batch.json, r.json, …)."""
    cfg = _config(config)
    sets = _datasets(datasets)
    per, summary, combined, fit_handle, fit_error = _core._batch(
        cfg, [d._tuple() for d in sets], order,
        out=None if out is None else os.fspath(out), noise_radius=noise_radius,
        jobs=jobs, max_order=max_order)
    results = [DatasetResult(Record.from_json(js).to_dict(), env, row) for js, env, row in per]
    fit = None if fit_handle is None else Fit(fit_handle)
    return BatchResult(results, summary, combined, fit, fit_error)
