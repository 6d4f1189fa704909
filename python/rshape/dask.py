"""Batch at scale on Dask: map envelope + check + fit over datasets on a cluster and merge
the rows into a table identical to ``rshape batch``'s ``summary.csv``.

Example (a local cluster of 2 workers; on a real cluster give ``Client`` its address)::

    from dask.distributed import Client, LocalCluster
    import rshape, rshape.dask

    datasets = rshape.discover(data_dir="runs/")          # named as `rshape batch` does
    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        results = rshape.dask.map_datasets(client, "model.toml", datasets)
    open("summary.csv", "w").write(rshape.dask.summary_csv(results))

Each task loads the config on its worker (configs travel as a path or pickled as their
text), runs :func:`rshape.run_dataset` (the batch's envelope and check) and, when the
dataset succeeded and ``fit_order`` is not None, fits one r above that dataset's envelope.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, List, Optional, Sequence, Union

from ._api import Fit, fit
from ._batch import Dataset, DatasetResult, run_dataset
from ._batch import summary_csv as _summary_csv
from ._rshape import Config, FitError


@dataclass
class DatasetOutcome:
    """What one Dask task returns: the batch's result for the dataset and, when asked
    for, the r fitted above its envelope (``fit``) or why that fit failed (``fit_error``)."""

    result: DatasetResult
    fit: Optional[Fit] = None
    fit_error: Optional[str] = None

    def __reduce__(self):
        fit_json = None if self.fit is None else self.fit.json
        return (_rebuild_outcome, (self.result, fit_json, self.fit_error))


class _JsonFit:
    """A Fit rebuilt from r.json after pickling (no Rust handle: freqresp via numpy)."""

    def __init__(self, text: str):
        import json
        self.json = text
        self._r = json.loads(text)

    def freqresp(self, omega):
        import numpy as np
        s = 1j * np.asarray(omega, dtype=float)
        return np.polyval(self._r["num"], s) / np.polyval(self._r["den"], s)


def _rebuild_outcome(result, fit_json, fit_error):
    return DatasetOutcome(result, None if fit_json is None else Fit(_JsonFit(fit_json)), fit_error)


def process(dataset: Dataset, config: Union[str, Config], fit_order: Union[str, int, None] = "auto",
            noise_radius: Optional[float] = None) -> DatasetOutcome:
    """One task: envelope + check of ``dataset`` (as ``rshape batch``), then the fit of r
    above its envelope (``fit_order`` "auto", an int, or None to skip)."""
    cfg = config if isinstance(config, Config) else Config.load(os.fspath(config))
    res = run_dataset(cfg, dataset, noise_radius=noise_radius)
    out = DatasetOutcome(res)
    if res.ok and res.envelope is not None and fit_order is not None:
        try:
            out.fit = fit(res.envelope, order=fit_order)
        except FitError as e:
            out.fit_error = str(e)
    return out


def map_datasets(client: Any, config: Union[str, "os.PathLike[str]", Config],
                 datasets: Sequence[Dataset], fit_order: Union[str, int, None] = "auto",
                 noise_radius: Optional[float] = None) -> List[DatasetOutcome]:
    """``client.map`` of :func:`process` over ``datasets`` (a ``distributed.Client``);
    returns the outcomes in dataset order."""
    cfg = os.fspath(config) if isinstance(config, (str, os.PathLike)) else config
    futures = client.map(process, list(datasets), config=cfg, fit_order=fit_order,
                         noise_radius=noise_radius, pure=False)
    outs = client.gather(futures)
    return sorted(outs, key=lambda o: o.result.index)


def summary_csv(outcomes: Sequence[Union[DatasetOutcome, DatasetResult]]) -> str:
    """The merged table: ``summary.csv`` as ``rshape batch`` writes it."""
    return _summary_csv([o.result if isinstance(o, DatasetOutcome) else o for o in outcomes])
