"""Bad input from Python raises a clear exception (never a crash), and the fitted r from
.to_control() lies above the envelope at every datum, evaluated by python-control."""

import numpy as np
import pytest

import rshape
from conftest import CONFIGS, ROOT

SISO = CONFIGS / "plant_first.toml"


def data():
    f = rshape.read_frf(CONFIGS / "plant_first.csv")
    return np.asarray(f.omega), np.asarray(f.response)


def test_frf_from_numpy_gives_the_file_s_envelope():
    cfg = rshape.Config.load(SISO)
    w, g = data()
    from_file = rshape.envelope(cfg)
    from_numpy = rshape.envelope(cfg, rshape.Frf(w, g))
    from_siso = rshape.envelope(cfg, rshape.Frf(w, g[:, 0, 0]))
    assert np.array_equal(from_file.r_min, from_numpy.r_min)
    assert np.array_equal(from_file.r_min, from_siso.r_min)
    # The same data through the arrays the Frf gives back.
    back = rshape.Frf(rshape.Frf(w, g).omega, rshape.Frf(w, g).response)
    assert np.array_equal(rshape.envelope(cfg, back).r_min, from_file.r_min)


@pytest.mark.parametrize(
    "make,words",
    [
        (lambda w, g: rshape.Frf(w[::-1], g), "increase strictly"),
        (lambda w, g: rshape.Frf(np.r_[w[:3], w[2], w[4:]], g), "increase strictly"),
        (lambda w, g: rshape.Frf(w, g[:-1]), "shape"),
        (lambda w, g: rshape.Frf(w, g.reshape(len(w), 1)), "shape"),
        (lambda w, g: rshape.Frf(w, np.where(np.arange(len(w))[:, None, None] == 5, np.nan, g)), "omega[5]"),
        (lambda w, g: rshape.Frf(np.where(np.arange(len(w)) == 2, np.nan, w), g), "omega[2]"),
        (lambda w, g: rshape.Frf(-w, g), "not positive"),
        (lambda w, g: rshape.Frf(w, g, noise_radius=np.ones(3)), "noise_radius"),
        (lambda w, g: rshape.Frf(w, g, coherence=np.full(len(w), 0.9)), "averages"),
        (lambda w, g: rshape.Frf(np.empty(0), np.empty(0, complex)), "empty"),
    ],
)
def test_bad_arrays_raise_input_error(make, words):
    w, g = data()
    with pytest.raises(rshape.InputError) as e:
        make(w, g)
    assert words in str(e.value)
    assert "\n" not in str(e.value)


def test_wrong_size_for_the_model_names_the_data(tmp_path):
    cfg = rshape.Config.load(CONFIGS / "paper_mimo.toml")
    w, g = data()
    with pytest.raises(rshape.InputError) as e:
        rshape.envelope(cfg, rshape.Frf(w, g, name="mine.csv"))
    assert "mine.csv" in str(e.value)


def test_missing_files_raise_with_the_cli_message(cli, tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(rshape.InputError) as e:
        rshape.Config.load(missing)
    p = cli("envelope", missing, "--out", tmp_path / "o", check=False)
    assert p.returncode == 2
    assert p.stderr.strip() == f"error: {e.value}"
    with pytest.raises(rshape.InputError, match="not found"):
        rshape.read_frf(tmp_path / "nope.csv")


def test_malformed_config_raises_with_the_cli_message(cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[plant]\ntf = [[{ num = [1], den = [0] }]]\n")
    with pytest.raises(rshape.InputError) as e:
        rshape.Config.load(bad)
    p = cli("envelope", bad, "--out", tmp_path / "o", check=False)
    assert p.stderr.strip() == f"error: {e.value}"


def test_r_that_is_not_a_unit_is_not_admissible():
    cfg = rshape.Config.load(SISO)
    env = rshape.envelope(cfg)
    with pytest.raises(rshape.NotAdmissible, match="not a unit"):
        rshape.check(([1.0], [1.0, -1.0]), env)  # unstable pole
    with pytest.raises(rshape.NotAdmissible):
        rshape.check(([1.0, 1.0], [1.0, 1.0, 1.0]), env)  # strictly proper


def test_other_bad_arguments():
    cfg = rshape.Config.load(SISO)
    env = rshape.envelope(cfg)
    with pytest.raises(rshape.InputError, match="order"):
        rshape.fit(env, order="best")
    with pytest.raises(rshape.InputError, match="noise_radius"):
        rshape.envelope(cfg, noise_radius=float("nan"))
    with pytest.raises(rshape.InputError, match="method"):
        rshape.synthesize(cfg, method="lqg")
    with pytest.raises(rshape.InputError, match="controller"):
        rshape.stability(cfg, object())
    with pytest.raises(rshape.InputError, match="no data file"):
        rshape.envelope(rshape.Config.from_toml("[plant]\ntf = [[{ num = [1], den = [1, 1, 0] }]]\n"))
    # Every rshape exception is an RshapeError.
    assert issubclass(rshape.NotAdmissible, rshape.RshapeError)
    assert issubclass(rshape.InputError, rshape.RshapeError)


@pytest.mark.parametrize("name", ["plant_first.toml", "paper_mimo.toml", "robot.toml"])
def test_to_control_lies_above_the_envelope_at_every_datum(name):
    control = pytest.importorskip("control")
    cfg = rshape.Config.load(CONFIGS / name)
    env = rshape.envelope(cfg)
    f = rshape.fit(env)
    r = f.to_control()
    assert isinstance(r, control.TransferFunction)
    # python-control's own evaluation of r(jw), and numpy's polyval of its coefficients:
    # routes independent of rshape's.
    mag = np.abs(np.asarray([complex(r(1j * w)) for w in env.omega]))
    num, den = np.asarray(r.num[0][0]), np.asarray(r.den[0][0])
    mag_np = np.abs(np.polyval(num, 1j * env.omega) / np.polyval(den, 1j * env.omega))
    assert (mag >= env.r_min).all(), np.min(mag / env.r_min)
    assert (mag_np >= env.r_min).all()
    # r is a unit of RH-infinity: poles and zeros in the open left half-plane.
    assert (np.real(control.poles(r)) < 0).all() and (np.real(control.zeros(r)) < 0).all()
    # freqresp agrees with python-control.
    assert np.allclose(f.freqresp(env.omega), [complex(r(1j * w)) for w in env.omega], rtol=1e-12)


def test_config_pickles_for_workers():
    import pickle
    cfg = rshape.Config.load(SISO)
    back = pickle.loads(pickle.dumps(cfg))
    assert back.path == cfg.path and back.r == cfg.r
    assert np.array_equal(rshape.envelope(back).r_min, rshape.envelope(cfg).r_min)


def test_long_calls_release_the_gil():
    import threading
    import time

    cfg = rshape.Config.load(SISO)
    env = rshape.envelope(cfg)
    done = threading.Event()
    ticks = 0

    def work():
        rshape.fit(env, order=5)
        done.set()

    t = threading.Thread(target=work)
    start = time.perf_counter()
    t.start()
    while not done.is_set():  # pure-Python work: runs only while the fit has no GIL
        ticks += 1
        time.sleep(0)
    t.join()
    elapsed = time.perf_counter() - start
    # With the GIL held for the whole fit this loop would see about one switch interval
    # (5 ms) of turns; it sees many while the fit runs.
    assert elapsed > 0.02 and ticks > 1000, (elapsed, ticks)
