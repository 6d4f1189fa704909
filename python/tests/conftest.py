"""Fixtures: the repository, the CLI binary built by cargo (the reference every number of
the Python package is compared with), and cached CLI runs."""

import json
import os
import subprocess
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = ROOT / "configs"


def _cli_binary() -> Path:
    env = os.environ.get("RSHAPE_BIN")
    if env:
        return Path(env)
    for p in (ROOT / "target" / "debug" / "rshape", ROOT / "target" / "release" / "rshape"):
        if p.exists():
            return p
    subprocess.run(["cargo", "build", "--bin", "rshape"], cwd=ROOT, check=True)
    return ROOT / "target" / "debug" / "rshape"


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """Runs the CLI; returns the completed process (text)."""
    exe = _cli_binary()

    def run(*args, check=True):
        p = subprocess.run([str(exe), *map(str, args)], cwd=ROOT, capture_output=True, text=True)
        if check and p.returncode not in (0, 1, 3):
            raise AssertionError(f"rshape {' '.join(map(str, args))}: exit {p.returncode}: {p.stderr}")
        return p

    return run


# The configs of the selected tests that take `cli_run` and a `name` parameter, in run order.
_PREFETCH: list = []


def pytest_collection_finish(session):
    """After selection (`-k`, node ids): what `cli_run` starts ahead."""
    for item in session.items:
        params = getattr(getattr(item, "callspec", None), "params", {})
        if "cli_run" in getattr(item, "fixturenames", ()) and "name" in params and params["name"] not in _PREFETCH:
            _PREFETCH.append(params["name"])


@pytest.fixture(scope="session")
def cli_run(cli, tmp_path_factory):
    """`rshape run CONFIG --out DIR` once per config: the DIR.

    The runs the selected tests will ask for (`_PREFETCH`, in the order they run) start in the
    background at once, on one core fewer than the machine's (at least one thread: the CLI is a
    separate process), so that they overlap the Python side's own computations; `run(config)`
    waits for its config's run. The runs and what the tests compare are the same either way."""
    pool = ThreadPoolExecutor(max_workers=max(1, (os.cpu_count() or 2) - 1))
    started = {}

    def one(config: str, out: Path):
        p = cli("run", CONFIGS / config, "--out", out, check=False)
        return out, p.stderr.strip() if p.returncode == 2 else None

    def start(config: str):
        if config not in started:
            started[config] = pool.submit(one, config, tmp_path_factory.mktemp(Path(config).stem))

    def run(config: str):
        """The output folder, and the error line when the CLI refused the config (exit 2)."""
        start(config)
        return started[config].result()

    for config in _PREFETCH:
        start(config)
    yield run
    for f in started.values():  # nothing left running past the session
        f.cancel()
    pool.shutdown(wait=True)


def read_envelope_csv(path: Path):
    rows = [line.split(",") for line in path.read_text().splitlines() if line and not line.startswith("#")]
    head, body = rows[0], rows[1:]
    cols = {name: [float(r[i]) if r[i] != "" else float("nan") for r in body] for i, name in enumerate(head)}
    return cols


def read_json(path: Path):
    return json.loads(path.read_text())
