"""The dataset reader and the tracker fed frame by frame through Python, against
`omnivert track` on the same dataset; bad datasets."""
import csv
import shutil

import numpy as np
import pytest

import omnivert
from conftest import cli


def test_dataset_reader(short_run):
    ds = omnivert.Dataset(str(short_run))
    rows = (short_run / "cam0" / "data.csv").read_text().splitlines()[1:]
    assert len(ds) == len(rows) == 12
    np.testing.assert_array_equal(ds.timestamps, [int(r.split(",")[0]) for r in rows])
    image = ds.image(0)
    assert image.dtype == np.uint8 and image.shape == (ds.camera.height, ds.camera.width)
    assert ds.has_wheel and ds.wheel_base == pytest.approx(0.40)
    # The increments sum to the travel between the first and the last image.
    travel = ds.travel_at_images
    np.testing.assert_allclose(ds.increments.sum(axis=0),
                               [travel[-1, 1] - travel[0, 1], travel[-1, 0] - travel[0, 0]],
                               rtol=0, atol=1e-12)
    assert ds.ground_truth["extrinsics"]["phi"] == pytest.approx(-0.34)
    with pytest.raises(IndexError):
        ds.image(len(ds))


def test_frame_by_frame_tracking_same_as_cli(short_run, tmp_path):
    cli("track", short_run, "--out", tmp_path / "trk")
    with open(tmp_path / "trk" / "tracks.csv", newline="") as f:
        expected = [(int(r["frame"]), int(r["track_id"]), r["bearing_rad"])
                    for r in csv.DictReader(f)]
    ds = omnivert.Dataset(str(short_run))
    pipe = omnivert.FeaturePipeline(ds.camera)
    tracker = omnivert.Tracker(wheel_base=ds.wheel_base)
    got = []
    for i, (d_right, d_left) in enumerate(ds.increments):
        features = pipe.process(ds.image(i))
        ids = tracker.add_frame(features, d_right, d_left).track_ids
        got += [(i, int(t), b) for t, b in zip(ids, features.bearings)]
    assert [(f, t) for f, t, _ in got] == [(f, t) for f, t, _ in expected]
    # tracks.csv prints bearings with 9 decimals.
    assert [f"{b:.9f}" for _, _, b in got] == [e for _, _, e in expected]
    assert tracker.frames_seen == 12 and tracker.stats["lines"] == len(expected)
    # The camera's yaw given from the start, as `track --camera-yaw`.
    cli("track", short_run, "--out", tmp_path / "yaw", "--camera-yaw", "0.2")
    with open(tmp_path / "yaw" / "tracks.csv", newline="") as f:
        given = [(int(r["frame"]), int(r["track_id"])) for r in csv.DictReader(f)]
    told = omnivert.Tracker(wheel_base=ds.wheel_base)
    told.set_camera_yaw(0.2)
    got = []
    for i, (d_right, d_left) in enumerate(ds.increments):
        ids = told.add_frame(pipe.process(ds.image(i)), d_right, d_left).track_ids
        got += [(i, int(t)) for t in ids]
    assert got == given
    # Without the wheel base the gate is off and the ids can differ, but every line is tracked.
    plain = omnivert.Tracker()
    assert len(plain.add_frame(pipe.process(ds.image(0)))) > 0
    assert len(plain.add_frame(None)) == 0


def test_track_dataset_same_as_cli(short_run, tmp_path):
    cli("track", short_run, "--out", tmp_path / "cli")
    r = omnivert.track_dataset(str(short_run), str(tmp_path / "py"), progress=False)
    assert ((tmp_path / "py" / "tracks.csv").read_text()
            == (tmp_path / "cli" / "tracks.csv").read_text())
    with open(tmp_path / "cli" / "tracks.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert r["tracks"]["track_id"].tolist() == [int(x["track_id"]) for x in rows]
    assert r["frames"] == 12 and r["stats"]["lines"] == len(rows)
    # The paper's rules give other tracks (no gate, F1 1.05), as `track --rules paper`.
    cli("track", short_run, "--out", tmp_path / "paper", "--rules", "paper")
    p = omnivert.track_dataset(str(short_run), str(tmp_path / "py-paper"), rules="paper",
                               progress=False)
    assert ((tmp_path / "py-paper" / "tracks.csv").read_text()
            == (tmp_path / "paper" / "tracks.csv").read_text())
    assert p["stats"]["rejected_gate"] == 0


def test_missing_wheel_data_same_message_as_cli(short_run, tmp_path):
    broken = tmp_path / "broken"
    shutil.copytree(short_run, broken)
    (broken / "wheel0" / "data.csv").unlink()
    err = cli("track", broken, "--out", tmp_path / "trk", expect=2).stderr
    with pytest.raises(omnivert.InputError) as e:
        omnivert.Dataset(str(broken))
    assert str(e.value) in err
    assert "wheel0" in str(e.value)


def test_tracker_options():
    with pytest.raises(TypeError, match="look_bak"):
        omnivert.Tracker(look_bak=3)
    with pytest.raises(omnivert.InputError, match="look-back"):
        omnivert.Tracker(look_back=0)
    with pytest.raises(omnivert.InputError, match="rules"):
        omnivert.Tracker(rules="mine")
