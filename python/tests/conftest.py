"""Fixtures: the repository, the CLI binary built by cargo (the reference every number of
the Python package is compared with), and cached CLI runs."""

import json
import os
import subprocess
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


@pytest.fixture(scope="session")
def cli_run(cli, tmp_path_factory):
    """`rshape run CONFIG --out DIR` once per config: the DIR."""
    cache = {}

    def run(config: str):
        """The output folder, and the error line when the CLI refused the config (exit 2)."""
        if config not in cache:
            out = tmp_path_factory.mktemp(Path(config).stem)
            p = cli("run", CONFIGS / config, "--out", out, check=False)
            cache[config] = (out, p.stderr.strip() if p.returncode == 2 else None)
        return cache[config]

    return run


def read_envelope_csv(path: Path):
    rows = [line.split(",") for line in path.read_text().splitlines() if line and not line.startswith("#")]
    head, body = rows[0], rows[1:]
    cols = {name: [float(r[i]) if r[i] != "" else float("nan") for r in body] for i, name in enumerate(head)}
    return cols


def read_json(path: Path):
    return json.loads(path.read_text())
