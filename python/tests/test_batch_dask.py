"""Batch: `rshape.batch` and the Dask example (a LocalCluster of 2 workers) give the
summary.csv of `rshape batch` byte for byte on the same datasets, a failing one included."""

import shutil

import numpy as np
import pytest

import rshape
from conftest import CONFIGS

CONFIG = CONFIGS / "plant_first.toml"


@pytest.fixture(scope="module")
def data_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("runs")
    src = (CONFIGS / "plant_first.csv").read_text().splitlines()
    shutil.copy(CONFIGS / "plant_first.csv", d / "a_nominal.csv")
    # Two more "experiments": the response scaled by 1.05 and by 0.9 (gain drift).
    for name, k in (("b_drift.csv", 1.05), ("c_weak.csv", 0.9)):
        out = []
        for line in src:
            parts = line.split(",")
            try:
                vals = [float(x) for x in parts]
            except ValueError:
                out.append(line)
                continue
            out.append(",".join([repr(vals[0])] + [repr(k * v) for v in vals[1:]]))
        (d / name).write_text("\n".join(out) + "\n")
    # A bad dataset: a value that is not a number. The batch goes on past it.
    lines = src[:]
    body = [i for i, l in enumerate(lines) if l and l[0].isdigit()]
    parts = lines[body[3]].split(",")
    lines[body[3]] = ",".join(parts[:1] + ["x"] + parts[2:])
    (d / "d_bad.csv").write_text("\n".join(lines) + "\n")
    return d


@pytest.fixture(scope="module")
def cli_batch(cli, data_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli_batch")
    p = cli("batch", CONFIG, "--data-dir", data_dir, "--out", out)
    assert p.returncode == 3  # one dataset failed
    return out


def test_batch_equals_the_cli(cli_batch, data_dir, tmp_path):
    res = rshape.batch(CONFIG, rshape.discover(data_dir=data_dir), out=tmp_path / "b")
    expected = (cli_batch / "summary.csv").read_text()
    assert res.summary_csv == expected
    assert (tmp_path / "b" / "summary.csv").read_text() == expected
    assert res.n_failed == 1 and "d_bad" in [r.name for r in res.results if not r.ok]
    cli_r = __import__("json").loads((cli_batch / "r.json").read_text())
    assert list(res.fit.num) == cli_r["num"] and list(res.fit.den) == cli_r["den"]
    # Without out: the same table and the same fit, nothing written.
    res2 = rshape.batch(CONFIG, data_dir)
    assert res2.summary_csv == expected
    assert np.array_equal(res2.fit.num, res.fit.num)


def test_dask_map_merges_into_the_cli_summary(cli_batch, data_dir):
    distributed = pytest.importorskip("dask.distributed")
    import rshape.dask

    datasets = rshape.discover(data_dir=data_dir)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        outcomes = rshape.dask.map_datasets(client, str(CONFIG), datasets)
        # The tasks ran on both workers' processes (not in this one).
        assert len(client.scheduler_info()["workers"]) == 2
    table = rshape.dask.summary_csv(outcomes)
    assert table == (cli_batch / "summary.csv").read_text()
    # Each good dataset got its own certified r above its own envelope.
    for o in outcomes:
        if o.result.ok:
            assert o.fit is not None and o.fit.certificate.passed
            env = o.result.envelope
            assert (np.abs(o.fit.freqresp(env.omega)) >= env.r_min).all()
        else:
            assert o.fit is None and "d_bad.csv" in o.result.error
