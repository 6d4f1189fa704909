"""The ```python blocks of docs/guide/python.md run, in order, in one namespace, from the
repository's root (the matplotlib block is skipped when matplotlib is absent)."""

import importlib.util
import os
import re

import pytest

from conftest import ROOT

PAGE = ROOT / "docs" / "guide" / "python.md"


def blocks():
    text = PAGE.read_text()
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_the_page_has_the_worked_example():
    b = blocks()
    assert len(b) >= 8
    joined = "\n".join(b)
    for call in ("rshape.envelope", "rshape.fit", "to_control()", "rshape.stability", "savefig", "dask"):
        assert call in joined


def test_python_guide_blocks_run(tmp_path):
    ns: dict = {}
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        for i, code in enumerate(blocks()):
            if "import matplotlib" in code and importlib.util.find_spec("matplotlib") is None:
                continue
            try:
                exec(compile(code, f"{PAGE.name} block {i + 1}", "exec"), ns)
            except Exception as e:  # name the block in the failure
                pytest.fail(f"{PAGE.name} block {i + 1} failed: {type(e).__name__}: {e}")
    finally:
        os.chdir(cwd)
    if importlib.util.find_spec("matplotlib") is not None:
        assert (ROOT / "out" / "python" / "r_vs_delta.png").stat().st_size > 10_000
