"""Every number of the Python package equals the CLI's for the same inputs (to 1e-12
relative): envelope, check verdict, fit coefficients on the shipped configs; alpha* of
`rshape stability`; gamma and alpha of `rshape synthesize`. The CLI is the separately built
binary, read through its output files (17 significant digits, or JSON)."""

import json
from pathlib import Path

import numpy as np
import pytest

import rshape
from conftest import CONFIGS, read_envelope_csv, read_json

# Every shipped config that names a data file (the controllers and robot_physical do not).
DATA_CONFIGS = sorted(
    p.name for p in CONFIGS.glob("*.toml") if any(l.startswith("data") for l in p.read_text().splitlines())
)

TOL = 1e-12


def close(a, b, tol=TOL):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape, (a.shape, b.shape)
    same_inf = np.isinf(a) & np.isinf(b) & (np.sign(a) == np.sign(b))
    with np.errstate(invalid="ignore"):  # inf - inf where both are inf: same_inf covers it
        ok = same_inf | (np.abs(a - b) <= tol * np.maximum(1.0, np.maximum(np.abs(a), np.abs(b))))
    assert ok.all(), f"max difference {np.nanmax(np.abs(a - b)[~same_inf])}"


def test_the_shipped_configs_are_covered():
    assert len(DATA_CONFIGS) >= 15
    assert "paper_mimo.toml" in DATA_CONFIGS and "closed_loop_same_noisy.toml" in DATA_CONFIGS


@pytest.mark.parametrize("name", DATA_CONFIGS)
def test_envelope_check_and_fit_equal_the_cli(name, cli_run):
    out, error = cli_run(name)
    cfg = rshape.Config.load(CONFIGS / name)
    if error is not None:
        # The CLI refuses this config for `run` (e.g. noisy MIMO data): Python raises the
        # same one-line message.
        with pytest.raises(rshape.RshapeError) as e:
            rshape.envelope(cfg)
        assert error == f"error: {e.value}"
        return
    env = rshape.envelope(cfg)
    csv = read_envelope_csv(out / "envelope.csv")
    close(env.omega, csv["omega_rad_s"])
    close(env.r_min, csv["r_min"])
    if env.a1_limit is not None and "a1_limit" in csv:
        close(env.a1_limit, csv["a1_limit"])
    report = read_json(out / "report.json")
    if cfg.r is not None and not cfg.closed_loop:
        chk = rshape.check(cfg, env)
        assert chk.verdict.value == report["verdict"]
    rj = out / "r.json"
    if rj.exists():
        cli_fit = read_json(rj)
        f = rshape.fit(env, order="auto")
        assert f.order == cli_fit["order"]
        close(f.num, cli_fit["num"])
        close(f.den, cli_fit["den"])
        close(f.gain, cli_fit["gain"])
        assert f.certificate.passed == cli_fit["certificate"]["passed"]
    else:
        with pytest.raises(rshape.FitError):
            rshape.fit(env, order="auto")


CONTROLLED = [
    ("plant_first.toml", "plant_first_controller.toml"),
    ("paper_mimo.toml", "paper_mimo_controller.toml"),
    ("robot.toml", "robot_controller.toml"),
]


@pytest.mark.parametrize("name,controller", CONTROLLED)
def test_stability_alpha_equals_the_cli(name, controller, cli, cli_run):
    out, _ = cli_run(name)
    p = cli("stability", CONFIGS / name, "--controller", CONFIGS / controller,
            "--r-json", out / "r.json", "--json")
    cli_rep = json.loads(p.stdout)
    r = read_json(out / "r.json")
    st = rshape.stability(CONFIGS / name, CONFIGS / controller, r=(r["num"], r["den"]))
    assert st.internally_stable == cli_rep["internally_stable"]
    assert [m.label for m in st.margins] == [m["label"] for m in cli_rep["margins"]]
    for m, c in zip(st.margins, cli_rep["margins"]):
        close(m.alpha, c["alpha"])
        close(m.alpha_lower, c["alpha_lower"])
        assert m.verdict == c["verdict"]
    assert st.robust == (p.returncode == 0)


@pytest.mark.parametrize("method", ["gm", "hinf"])
def test_synthesized_gamma_and_alpha_equal_the_cli(method, cli, cli_run, tmp_path):
    name = "plant_first.toml"
    out, _ = cli_run(name)
    p = cli("synthesize", CONFIGS / name, "--r-json", out / "r.json", "--method", method,
            "--out", tmp_path / "syn", "--json")
    cli_syn = json.loads(p.stdout)
    r = read_json(out / "r.json")
    s = rshape.synthesize(CONFIGS / name, method=method, r=(r["num"], r["den"]))
    assert s.method == cli_syn["method"]
    # `gamma` is the controller's: H∞'s with `gamma_opt`, or Glover–McFarlane's with
    # `gamma_min`; Glover–McFarlane's numbers are under `glover_mcfarlane` either way.
    own = ("gamma_opt",) if method == "hinf" else ("gamma_min",)
    for key in ("b_opt", "gamma") + own:
        close(s[key], cli_syn[key])
    for key in ("b_opt", "gamma_min", "gamma"):
        close(s["glover_mcfarlane"][key], cli_syn["glover_mcfarlane"][key])
    for b, c in zip(s.bounds, cli_syn["bounds"]):
        assert b.label == c["label"]
        close(b.alpha, c["alpha"])
    # The controller's matrices are those of controller.json.
    k = read_json(tmp_path / "syn" / "controller.json")
    for name_ in "ABCD":
        close(getattr(s, name_), np.asarray(k[name_], dtype=float).reshape(getattr(s, name_).shape))


def test_compare_and_diagnose_equal_the_cli(cli, tmp_path):
    name = CONFIGS / "twomass_rigid.toml"
    cmp_cli = json.loads(cli("compare", name, "--json").stdout)
    cmp_py = rshape.compare(name)
    assert cmp_py.to_dict() == cmp_cli
    d_cli = json.loads(cli("diagnose", name, "--json").stdout)
    d_py = rshape.diagnose(name)
    strip = lambda d: {k: v for k, v in d.items() if k != "search"}  # the search's timings differ
    assert strip(d_py.to_dict()) == strip(d_cli)
    assert len(d_py.candidates) > 0
    # apply("chosen") is the text `diagnose --apply chosen --write` writes.
    revised = tmp_path / "revised.toml"
    cli("diagnose", name, "--apply", "chosen", "--write", revised)
    assert d_py.apply("chosen", write=tmp_path / "py.toml") == revised.read_text()
    assert (tmp_path / "py.toml").read_text() == revised.read_text()
    # Without write: the text for a file beside the config, which loads from there.
    beside = d_py.apply("chosen")
    assert rshape.Config.from_toml(beside, CONFIGS / "revised.toml").data == rshape.Config.load(name).data
    assert not list(CONFIGS.glob(".rshape-revision-*"))


def test_diagnose_exclude_equals_the_cli(cli):
    """``exclude=`` leaves ranges of lines out as ``--exclude`` does; a range with no line
    is the CLI's error."""
    name = CONFIGS / "mains_line.toml"
    d_cli = json.loads(cli("diagnose", name, "--exclude", "2639.5:2640.5", "--exclude", "2500:2509",
                           "--json").stdout)
    d_py = rshape.diagnose(name, exclude=[(2639.5, 2640.5), (2500, 2509)])
    strip = lambda d: {k: v for k, v in d.items() if k != "search"}
    assert strip(d_py.to_dict()) == strip(d_cli)
    assert d_py.to_dict()["n_data"] == 290
    with pytest.raises(rshape.InputError, match="no line of the data lies in it"):
        rshape.diagnose(name, exclude=[(2640.2, 2640.3)])
