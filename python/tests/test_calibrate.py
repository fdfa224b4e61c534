"""The calibration through Python: calibrate_dataset against `omnivert calibrate` on the demo's
run (the same extrinsics.yaml to the last printed digit), calibrate() and the frame-by-frame
CalibrationFilter on a run of known geometry, and bad input."""
import json
import math

import numpy as np
import pytest

import omnivert
from conftest import cli

FIELDS = ["phi", "rho", "psi", "sigma_phi", "sigma_rho", "sigma_psi", "x", "y", "yaw"]


def yaml_values(path):
    """extrinsics.yaml's scalar fields and its covariance list, as printed."""
    values = {}
    for line in path.read_text().splitlines():
        key, _, value = line.partition(": ")
        if key in FIELDS:
            values[key] = value
        elif key == "covariance":
            values[key] = value.strip("[]").split(", ")
    return values


def test_calibrate_dataset_same_as_cli(demo_run, tmp_path):
    cli("calibrate", demo_run, "--out", tmp_path / "cli", "--refine")
    calls = []
    r = omnivert.calibrate_dataset(str(demo_run), str(tmp_path / "py"), refine=True,
                                   progress=lambda *a: calls.append(a))
    expected = yaml_values(tmp_path / "cli" / "extrinsics.yaml")
    e = r.extrinsics
    printed = {"phi": e.phi, "rho": e.rho, "psi": e.psi, "x": e.position[0],
               "y": e.position[1], "yaw": e.yaw}
    printed.update(zip(["sigma_phi", "sigma_rho", "sigma_psi"], np.sqrt(np.diag(r.covariance))))
    for key, value in printed.items():
        assert f"{value:.10g}" == expected[key], key
    assert [f"{v:.10g}" for v in r.covariance.ravel()] == expected["covariance"]
    # The files the two wrote are the same, line by line.
    assert ((tmp_path / "py" / "extrinsics.yaml").read_text()
            == (tmp_path / "cli" / "extrinsics.yaml").read_text())
    # summary.json: the same but for the command line and the wall times.
    cli_summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    for s in (cli_summary, r.summary):
        for key in ("command", "seconds"):
            s.pop(key)
        s.get("inputs", {}).pop("seconds", None)
    assert r.summary == cli_summary
    t = r.time_offset
    assert (t["offset_s"], t["sigma_s"]) == (r.summary["time_offset_s"], r.summary["time_offset_sigma_s"])
    assert t["refined"] == r.summary["time_offset"]["refined"] and t["message"] == r.summary["time_offset"]["message"]
    # The tracking, then the calibration's own stages (CalibrationOptions::progress).
    stages = [c[0] for c in calls]
    assert ("track", 93, 93) in calls and ("filter", 93, 93) in calls
    assert stages.index("calibrate") < stages.index("filter") < stages.index("refinement: first solve")
    assert calls[-1] == ("refinement: covariance", 0, 0)
    assert r.observable and r.calibration.source == "refinement"
    assert r.covariance.shape == (3, 3)
    assert r.calibration.observability.phi.determined
    truth = r.truth
    assert abs(e.rho - truth.rho) < 4 * math.sqrt(r.covariance[1, 1])


def known_run(frames_straight=30, frames_turn=30, seed=5):
    """Wheel increments and noise-free bearings of a robot that drives 2.3 m straight, then
    turns 180 degrees on the spot (the paper's experiment), among 16 vertical lines."""
    e, truth = 0.4, (-0.34, 0.23, 0.33)
    steps = [(2.3 / frames_straight,) * 2] * frames_straight
    arc = math.pi * e / 2 / max(frames_turn, 1)
    steps += [(arc, -arc)] * frames_turn
    rng = np.random.default_rng(seed)
    angles = np.linspace(-math.pi, math.pi, 16, endpoint=False)
    lines = np.c_[1.2 + 2.5 * np.cos(angles), 3.0 * np.sin(angles)] + rng.normal(0, 0.2, (16, 2))
    x = y = theta = 0.0
    increments, observations = [(0.0, 0.0)], []
    phi, rho, psi = truth
    for k in range(len(steps) + 1):
        if k > 0:
            d_right, d_left = steps[k - 1]
            d_rho, d_theta = (d_right + d_left) / 2, (d_right - d_left) / e
            x += d_rho * math.cos(theta + d_theta / 2)   # eq. (14)
            y += d_rho * math.sin(theta + d_theta / 2)
            theta += d_theta
            increments.append((d_right, d_left))
        cx = x + rho * math.cos(theta + phi)
        cy = y + rho * math.sin(theta + phi)
        for j, (lx, ly) in enumerate(lines):
            beta = math.atan2(ly - cy, lx - cx) - (theta + phi + psi)
            observations.append((k, j, math.atan2(math.sin(beta), math.cos(beta))))
    return np.array(increments), np.array(observations), truth


def test_streaming_dataset_same_as_cli(demo_run, tmp_path):
    """calibrate_dataset(streaming=True) gives `calibrate --streaming`'s estimate to the last
    printed digit, and streaming.csv has a row per frame (its times differ from run to run)."""
    cli("calibrate", demo_run, "--out", tmp_path / "cli", "--streaming")
    r = omnivert.calibrate_dataset(str(demo_run), str(tmp_path / "py"), streaming=True)
    assert ((tmp_path / "py" / "extrinsics.yaml").read_text()
            == (tmp_path / "cli" / "extrinsics.yaml").read_text())
    assert r.calibration.source == "filter" and r.summary["streaming"]["frames"] == 93
    rows = (tmp_path / "py" / "streaming.csv").read_text().splitlines()
    assert len(rows) == 94 and rows[0].startswith("frame,timestamp_ns,state,phi")
    assert rows[-1].split(",")[2] == "filter"
    with pytest.raises(omnivert.InputError, match="streaming gives the filter's estimate"):
        omnivert.calibrate_dataset(str(demo_run), str(tmp_path / "bad"), streaming=True, refine=True)


def test_calibrate_recovers_known_geometry():
    increments, observations, truth = known_run()
    r = omnivert.calibrate(increments, observations, wheel_base=0.4, refine=True)
    assert r.observable and r.refined
    e = r.extrinsics
    assert abs(e.phi - truth[0]) < 1e-4 and abs(e.rho - truth[1]) < 1e-4
    assert abs(e.psi - truth[2]) < 1e-4
    assert r.covariance.shape == (3, 3)
    np.testing.assert_allclose(r.covariance, r.covariance.T)
    assert len(r.history["phi"]) == len(increments)
    assert r.summary["result"]["source"] == "refinement"
    assert r.noise_check["verdict"] in ("agrees", "more noise", "less noise")


def test_straight_run_is_not_determined():
    increments, observations, _ = known_run(frames_turn=0)
    r = omnivert.calibrate(increments, observations, wheel_base=0.4)
    assert not r.observable
    assert not (r.observability.phi.determined and r.observability.rho.determined)
    assert "turn" in r.observability.message or "rotat" in r.observability.message


def test_streaming_filter_matches_calibrate():
    increments, observations, truth = known_run()
    f = omnivert.CalibrationFilter(wheel_base=0.4)
    for k, (d_right, d_left) in enumerate(increments):
        rows = observations[observations[:, 0] == k]
        f.process(d_right, d_left, rows[:, 1].astype(int).tolist(), rows[:, 2].tolist())
    f.finish()
    r = omnivert.calibrate(increments, observations, wheel_base=0.4)
    np.testing.assert_allclose([f.extrinsics.phi, f.extrinsics.rho, f.extrinsics.psi],
                               [r.filter_extrinsics.phi, r.filter_extrinsics.rho,
                                r.filter_extrinsics.psi], rtol=0, atol=1e-9)
    assert abs(f.extrinsics.rho - truth[1]) < 1e-3
    assert f.frames_processed == len(increments) == len(f.history["frame"])


def test_bad_input_raises_with_the_message():
    increments, observations, _ = known_run()
    observations[7, 2] = math.nan
    with pytest.raises(omnivert.InputError, match="finite|NaN|nan"):
        omnivert.calibrate(increments, observations, wheel_base=0.4)
    with pytest.raises(omnivert.InputError, match="frame 999"):
        omnivert.calibrate(increments, np.array([[999, 0, 0.1]]), wheel_base=0.4)
    with pytest.raises(omnivert.InputError, match="bearing_sigma"):
        omnivert.calibrate(increments, observations, bearing_sigma=-1.0)
    with pytest.raises(TypeError, match="refine"):
        omnivert.calibrate(increments, observations, refine="yes please")


def test_missing_dataset_same_message_as_cli(tmp_path):
    err = cli("calibrate", tmp_path / "none", "--out", tmp_path / "o1", expect=2).stderr
    with pytest.raises(omnivert.InputError) as e:
        omnivert.calibrate_dataset(str(tmp_path / "none"), str(tmp_path / "o2"))
    assert str(e.value) in err
