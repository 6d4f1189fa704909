"""A normalized frequency axis (DaISy FRFs, cycles/sample): the config's `sample_time` and
`read_frf(path, sample_time=...)` divide the frequencies by Ts; both routes give the CLI's
envelope (configs/daisy_robot_arm_h1.toml: noise from the coherence, Theorem 4)."""

import numpy as np
import pytest

import rshape


def test_read_frf_sample_time_divides_the_frequencies(root):
    path = root / "configs" / "data" / "daisy_robot_arm" / "frf_etfe_normfreq.csv"
    per_sample = rshape.read_frf(path)
    at_1khz = rshape.read_frf(path, sample_time=1e-3)
    np.testing.assert_allclose(at_1khz.omega, per_sample.omega / 1e-3, rtol=1e-15)
    assert per_sample.omega.max() <= np.pi  # below Nyquist in rad/sample
    with pytest.raises(Exception, match="sample_time"):
        rshape.read_frf(path, sample_time=0.0)


def test_config_sample_time_matches_the_cli(root, tmp_path, cli):
    cfg = rshape.Config.load(root / "configs" / "daisy_robot_arm_h1.toml")
    env = rshape.envelope(cfg)
    assert env.method == "theorem4_mu" and len(env.omega) == 52
    out = tmp_path / "o"
    cli("envelope", root / "configs" / "daisy_robot_arm_h1.toml", "--out", out)
    rows = np.loadtxt(out / "envelope.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(env.omega, rows[:, 0], rtol=1e-15)
    np.testing.assert_allclose(env.r_min, rows[:, 1], rtol=1e-12)
