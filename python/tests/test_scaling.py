"""[scaling] passes through the Python package: a config with [scaling] gives from numpy
arrays (scaled by the package, as the CLI scales the file) the envelope of its data file,
and the same envelope as the CLI."""

import numpy as np

import rshape
from conftest import CONFIGS


def test_scaled_config_scales_numpy_data_as_the_file(tmp_path, cli):
    text = (CONFIGS / "plant_first.toml").read_text()
    data = CONFIGS / "plant_first.csv"
    cfg_path = tmp_path / "scaled.toml"
    # [scaling] after every table of the copied config; the data path made absolute.
    lines = [
        f'data = "{data}"' if line.startswith("data =") else line
        for line in text.splitlines()
    ]
    cfg_path.write_text("\n".join(lines) + "\n\n[scaling]\noutputs = [0.01]\ninputs = [5.0]\n")
    cfg = rshape.Config.load(cfg_path)
    f = rshape.read_frf(data)
    from_file = rshape.envelope(cfg)
    from_numpy = rshape.envelope(cfg, rshape.Frf(np.asarray(f.omega), np.asarray(f.response)))
    assert np.allclose(from_file.r_min, from_numpy.r_min, rtol=1e-12, atol=0)
    # The CLI's envelope of the same config.
    out = tmp_path / "out"
    cli("envelope", cfg_path, "--out", out)
    rows = np.loadtxt(out / "envelope.csv", delimiter=",", skiprows=1, ndmin=2)
    assert np.allclose(rows[:, 1], from_file.r_min, rtol=1e-12, atol=0)
    # Unscaled, the envelope differs (the normalized factors of another plant).
    plain = rshape.envelope(rshape.Config.load(CONFIGS / "plant_first.toml"))
    assert not np.allclose(plain.r_min, from_file.r_min, rtol=1e-3)



def test_scaled_synthesis_gives_the_controller_of_the_unscaled_plant(tmp_path, cli):
    # Python writes the controller the CLI writes for a scaled config, K = D_i·K_s·D_o (the
    # controller of G itself), not the K_s designed for G_s = D_o·G·D_i.
    text = (CONFIGS / "plant_first.toml").read_text()
    data = CONFIGS / "plant_first.csv"
    lines = [
        f'data = "{data}"' if line.startswith("data =") else line
        for line in text.splitlines()
    ]
    cfg_path = tmp_path / "scaled.toml"
    cfg_path.write_text("\n".join(lines) + "\n\n[scaling]\noutputs = [0.01]\ninputs = [5.0]\n")
    s = rshape.synthesize(cfg_path)
    out = tmp_path / "out"
    cli("synthesize", cfg_path, "--out", out)
    assert s.controller_toml.strip() == (out / "controller.toml").read_text().strip()


def _scaled_pair(tmp_path, noise):
    """plant_first with a noise, without and with [scaling] (d_o·d_i = 0.007)."""
    data = CONFIGS / "plant_first.csv"
    base = f'data = "{data}"\n{noise}[plant]\ntf = [[{{ num = [1], den = [1, 1, 0] }}]]\n'
    plain, scaled = tmp_path / "plain.toml", tmp_path / "scaled.toml"
    plain.write_text(base)
    scaled.write_text(base + "[scaling]\noutputs = [1e-3]\ninputs = [7.0]\n")
    return plain, scaled


def test_scaled_compare_gives_the_unscaled_verdict_line_by_line(tmp_path):
    # The noise radius is in the data file's units: Python scales it with the data, as the
    # CLI does, so each line's misfit and verdict are the unscaled config's.
    plain, scaled = _scaled_pair(tmp_path, "[noise]\nradius = 0.05\n")
    a, b = rshape.compare(plain).to_dict(), rshape.compare(scaled).to_dict()
    assert 0 < sum(r["invalid"] for r in a["rows"]) < len(a["rows"])
    assert [r["invalid"] for r in a["rows"]] == [r["invalid"] for r in b["rows"]]
    for x, y in zip(a["rows"], b["rows"]):
        assert np.isclose(y["noise_radius"], 0.007 * x["noise_radius"], rtol=1e-12, atol=0)
        assert np.isclose(x["misfit"], y["misfit"], rtol=1e-9, atol=0)
    assert a["verdict"] == b["verdict"]
    assert a["invalid_fraction"] == b["invalid_fraction"]


def test_scaled_diagnose_is_the_unscaled_one_and_apply_keeps_scaling(tmp_path, cli):
    # A radius small enough that an effect is added (the plant-first data have a lag).
    plain, scaled = _scaled_pair(tmp_path, "[noise]\nradius = 0.002\n")
    a, b = rshape.diagnose(plain), rshape.diagnose(scaled)
    assert a.to_dict()["chosen"] and a.to_dict()["chosen"] == b.to_dict()["chosen"]
    for x, y in zip(a.to_dict()["final_effects"], b.to_dict()["final_effects"]):
        assert x["effect"] == y["effect"]
        for k, v in x["params"].items():
            assert np.isclose(v, y["params"][k], rtol=1e-9, atol=0)
    # The revision keeps [scaling] and is what the CLI writes.
    text = b.apply("chosen", write=tmp_path / "rev_py.toml")
    assert "[scaling]" in text and "[[physical." in text
    cli("diagnose", scaled, "--apply", "chosen", "--write", tmp_path / "rev_cli.toml")
    body = lambda t: [l for l in t.splitlines() if not l.startswith("#")]
    assert body(text) == body((tmp_path / "rev_cli.toml").read_text())
    rshape.Config.load(tmp_path / "rev_py.toml")
