"""The module's conventions: keyword options with the command-line tool's defaults, the
InputError class, the simulator, the camera geometry."""
import re
import signal

import numpy as np
import pytest

import omnivert
from conftest import cli

# Keyword options whose flag has another name or unit, or that the flag's help gives as a
# range rather than a default.
NOT_FLAGS = {"fixed_center", "refine_center", "mutual", "gate", "join", "noise_check",
             "tilt_check", "force", "write_mask", "refine", "rules", "center"}


def help_defaults(command):
    """{flag: default} of `omnivert COMMAND --help` ('  --split-chi2 FLOAT:NUMBER >= 0=20')."""
    text = cli(command, "--help").stdout
    return {m.group(1).replace("-", "_"): m.group(2)
            for m in re.finditer(r"^\s+--([a-z0-9-]+) [A-Z][^\n]*?=([^\s=]+)(?:\s|$)", text,
                                 re.MULTILINE)}


@pytest.mark.parametrize("call,command", [("calibrate_dataset", "calibrate"),
                                          ("simulate", "simulate"), ("extract", "extract"),
                                          ("track_dataset", "track")])
def test_defaults_are_the_cli_defaults(call, command):
    flags = help_defaults(command)
    compared = 0
    for name, value in omnivert.defaults(call).items():
        if name in NOT_FLAGS or name not in flags or isinstance(value, (bool, str)):
            continue
        assert float(flags[name]) == pytest.approx(value, rel=1e-9), name
        compared += 1
    assert compared >= {"calibrate_dataset": 10, "simulate": 15, "extract": 8,
                        "track_dataset": 9}[call]


def test_input_error_is_a_value_error():
    assert issubclass(omnivert.InputError, ValueError)
    with pytest.raises(omnivert.InputError) as e:
        omnivert.read_image("/nonexistent/image.png")
    assert "/nonexistent/image.png" in str(e.value) and e.value.file == "/nonexistent/image.png"


def test_unknown_and_mistyped_options():
    with pytest.raises(TypeError, match="bearing_sigmaa"):
        omnivert.CalibrationFilter(bearing_sigmaa=0.1)
    with pytest.raises(TypeError, match="bins"):
        omnivert.FeaturePipeline(bins="many")
    with pytest.raises(omnivert.InputError, match="smoothing"):
        omnivert.FeaturePipeline(smoothing="gauss")
    with pytest.raises(ValueError, match="no call"):
        omnivert.defaults("nothing")


def test_simulate_writes_a_dataset(tmp_path):
    s = omnivert.simulate(str(tmp_path / "run"), world="office", trajectory="straight",
                          frames=3, seed=2, progress=False)
    assert s["frames"] == 3
    ds = omnivert.Dataset(str(tmp_path / "run"))
    assert len(ds) == 3
    with pytest.raises(omnivert.InputError):
        omnivert.simulate(str(tmp_path / "run"), frames=3)       # exists, no force
    err = cli("simulate", "--out", tmp_path / "w", "--world", "moon", expect=2).stderr
    with pytest.raises(omnivert.InputError) as e:
        omnivert.simulate(str(tmp_path / "w2"), world="moon")
    assert str(e.value) in err


def test_interrupted_simulation_leaves_no_dataset(tmp_path):
    def interrupt(stage, done, total):
        assert stage == "simulate" and total == 12
        if done == 3:
            signal.raise_signal(signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        omnivert.simulate(str(tmp_path / "run"), frames=12, progress=interrupt)
    assert not (tmp_path / "run").exists()
    assert [p.name for p in tmp_path.iterdir()] == []


def test_camera_geometry():
    g = omnivert.CameraGeometry(640, 480, center=(320.5, 240.25), r_min=60, r_max=215,
                                bearing_sign=-1)
    assert g.center.tolist() == [320.5, 240.25]
    assert g.bearing_of_image_angle(0.3) == pytest.approx(-0.3)
    assert g.image_angle_of_bearing(g.bearing_of_image_angle(1.0)) == pytest.approx(1.0)
    with pytest.raises(omnivert.InputError):
        g.bayer = "XYZW"


def test_match_finds_the_same_lines():
    rng = np.random.default_rng(1)
    d = rng.random((12, 192)).astype(np.float32)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    m = omnivert.match(d[[4, 7, 1]], d)
    assert m["best"].tolist() == [4, 7, 1]
    np.testing.assert_allclose(m["distance"], 0, atol=1e-3)
    assert m["verdict"][0] in ("accepted", "test2", "test3", "test1")


def test_match_leaves_out_an_area_an_occluder_changed():
    rng = np.random.default_rng(2)
    d = rng.random((2, 192)).astype(np.float32)
    q = d[[0]].copy()
    q[0, :64] = rng.random(64)  # the inner area changed, as by a person passing
    paper = omnivert.match(q, d)
    tolerant = omnivert.match(q, d, partial_area_scale=2.0)
    assert paper["distance"][0] == pytest.approx(np.linalg.norm(q[0] - d[0]), rel=1e-4)
    assert tolerant["distance"][0] == pytest.approx(0.0, abs=1e-3)
    with pytest.raises(omnivert.InputError):
        omnivert.match(q, d, partial_area_scale=0.5)
