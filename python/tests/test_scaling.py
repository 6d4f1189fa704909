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
