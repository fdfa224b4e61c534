"""Frame features through Python against `omnivert extract --json` on the same image, the
image layouts numpy gives, and bad images."""
import json
import pathlib

import numpy as np
import pytest

import omnivert
from conftest import REAL_DATA, cli, first_frame


def cli_json(image, *args):
    return json.loads(cli("extract", image, "--json", *args).stdout)


def assert_same_as_cli(f, j):
    assert f.center.tolist() == j["center"]
    assert (f.r_min, f.r_max) == (j["r_min"], j["r_max"])
    assert len(f) == len(j["lines"]) > 0
    for i, (line, jl) in enumerate(zip(f.lines, j["lines"])):
        assert line.bearing == jl["bearing"], i
        assert line.image_angle == jl["image_angle"], i
        assert (line.edge_pixels, line.polarity, line.crowded) == (
            jl["edge_pixels"], jl["polarity"], jl["crowded"]), i
        assert (line.r_inner, line.r_outer, line.significance) == (
            jl["r_inner"], jl["r_outer"], jl["significance"]), i
    d = np.array([jl["descriptor"] for jl in j["lines"]], dtype=np.float32)
    assert f.descriptors.dtype == np.float32 and f.descriptors.shape[0] == len(f)
    np.testing.assert_array_equal(f.descriptors, d)
    np.testing.assert_array_equal(f.bearings, [jl["bearing"] for jl in j["lines"]])


def test_simulated_frame_same_as_cli(short_run):
    image = first_frame(short_run)
    sensor = short_run / "cam0" / "sensor.yaml"
    f = omnivert.extract(omnivert.read_image(str(image)), str(sensor))
    assert_same_as_cli(f, cli_json(image, "--sensor", sensor))
    # The same through a FeaturePipeline, with the geometry read by load_camera_geometry.
    pipe = omnivert.FeaturePipeline(omnivert.load_camera_geometry(str(sensor)))
    g = pipe.process(omnivert.read_image(str(image)))
    np.testing.assert_array_equal(g.descriptors, f.descriptors)


def test_options_reach_the_extractor(short_run):
    image = first_frame(short_run)
    f = omnivert.extract(omnivert.read_image(str(image)), None, bins=16, line_threshold="fraction")
    assert f.descriptors.shape[1] == 96
    assert_same_as_cli(f, cli_json(image, "--bins", "16", "--line-threshold", "fraction"))


def test_image_layouts_give_the_same_lines(short_run):
    grey = omnivert.read_image(str(first_frame(short_run)))
    assert grey.dtype == np.uint8 and grey.ndim == 2
    sensor = str(short_run / "cam0" / "sensor.yaml")
    ref = omnivert.extract(grey, sensor)
    colour = np.repeat(grey[:, :, None], 3, axis=2)              # BGR, equal channels
    deep = grey.astype(np.uint16) * 257                           # 16 bits, full range
    padded = np.zeros((grey.shape[0], grey.shape[1] + 13), np.uint8)
    padded[:, 5:5 + grey.shape[1]] = grey
    strided = padded[:, 5:5 + grey.shape[1]]                      # a view with padded rows
    flipped = np.ascontiguousarray(grey[:, ::-1])[:, ::-1]        # negative strides: copied
    assert not strided.flags.c_contiguous
    for image in (colour, deep, strided, flipped, grey.astype(np.float32) / 255.0):
        f = omnivert.extract(image, sensor)
        np.testing.assert_array_equal(f.bearings, ref.bearings)
        if image.dtype != np.float32:
            np.testing.assert_array_equal(f.descriptors, ref.descriptors)


def test_threads_extract_in_parallel_with_the_same_result(short_run):
    """process releases the GIL: pipelines of two threads run at once, each its own."""
    from concurrent.futures import ThreadPoolExecutor
    ds = omnivert.Dataset(str(short_run))
    images = [ds.image(i) for i in range(len(ds))]

    def run(_):
        pipe = omnivert.FeaturePipeline(ds.camera)
        return [pipe.process(im).bearings for im in images]

    ref = run(0)

    with ThreadPoolExecutor(2) as pool:
        for got in pool.map(run, range(4)):
            for g, r in zip(got, ref):
                np.testing.assert_array_equal(g, r)


def test_descriptor_view_is_read_only(short_run):
    f = omnivert.extract(omnivert.read_image(str(first_frame(short_run))))
    with pytest.raises(ValueError):
        f.descriptors[0, 0] = 1.0


@pytest.mark.parametrize("image,words", [
    (np.zeros((48, 64, 2), np.uint8), "2 channels"),
    (np.zeros((48, 64), np.float64), "not supported"),
    (np.zeros((0, 64), np.uint8), "empty"),
    (np.zeros(64, np.uint8), "1 dimensions"),
])
def test_bad_arrays_raise_input_error(image, words):
    with pytest.raises(omnivert.InputError, match=words):
        omnivert.extract(image)


@pytest.mark.parametrize("name", ["one-pixel.png", "black.png", "noise.png", "gradient.png"])
def test_hostile_images_raise_or_give_finite_lines(name):
    """The CLI's hostile images (tests/tools/data): an InputError with the reason, or lines
    without a NaN."""
    path = pathlib.Path(__file__).parents[2] / "tests" / "tools" / "data" / name
    image = omnivert.read_image(str(path))
    try:
        f = omnivert.extract(image)
    except omnivert.InputError as e:
        assert str(e).startswith("image: ") and len(str(e)) > 12
        cli("extract", path, expect=2)
        return
    assert np.isfinite(f.bearings).all() and np.isfinite(f.descriptors).all()
    assert np.isfinite(f.center).all()
    cli("extract", path)


def test_wrong_size_raises_the_cli_message(short_run, tmp_path):
    small = omnivert.read_image(str(first_frame(short_run)))[:240, :320]
    sensor = short_run / "cam0" / "sensor.yaml"
    path = tmp_path / "small.png"
    omnivert.write_image(str(path), small)
    np.testing.assert_array_equal(omnivert.read_image(str(path)), small)
    err = cli("extract", path, "--sensor", sensor, expect=2).stderr
    with pytest.raises(omnivert.InputError) as e:
        omnivert.extract(small, str(sensor))
    reason = str(e.value).split("image: ", 1)[1]
    assert "320" in reason and reason in err


def test_bad_sensor_yaml_raises_with_file_and_line(short_run, tmp_path):
    bad = tmp_path / "sensor.yaml"
    bad.write_text("resolution: [640, 480]\nr_min: 90\nr_max: 80\n")
    with pytest.raises(omnivert.InputError) as e:
        omnivert.load_camera_geometry(str(bad))
    assert isinstance(e.value, ValueError)
    assert e.value.file == str(bad) and e.value.line > 0
    err = cli("extract", first_frame(short_run), "--sensor", bad, expect=2).stderr
    assert str(e.value) in err


@pytest.mark.skipif(not REAL_DATA.is_dir(), reason="the real sample images are absent")
def test_real_image_same_as_cli():
    image = sorted(p for p in REAL_DATA.rglob("*") if p.suffix.lower() in (".png", ".jpg"))[0]
    f = omnivert.extract(omnivert.read_image(str(image)))
    assert_same_as_cli(f, cli_json(image))
