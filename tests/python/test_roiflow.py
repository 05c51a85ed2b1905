"""The Python module against the CLI: same flow, same errors, same tracks.

Run by ctest (tests/CMakeLists.txt) with PYTHONPATH at the build tree, ROIFLOW_CLI the roiflow
binary, ROIFLOW_BUILD_DIR the build tree and ROIFLOW_DATA the shared data (may be absent).
"""
import os
import re
import subprocess
import sys
import threading

import numpy as np
import pytest

import roiflow

CLI = os.environ.get("ROIFLOW_CLI", "roiflow")
DATA = os.environ.get("ROIFLOW_DATA", "")


def write_pgm(path, image):
    image = np.ascontiguousarray(image, dtype=np.uint8)
    with open(path, "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (image.shape[1], image.shape[0]))
        f.write(image.tobytes())


def texture(h, w, seed=1):
    """Smooth random texture, uint8, enough gradient everywhere for LK."""
    rng = np.random.default_rng(seed)
    noise = rng.random((h + 8, w + 8))
    for _ in range(2):  # box blur 5x5 twice
        noise = sum(np.roll(np.roll(noise, dy, 0), dx, 1)
                    for dy in range(-2, 3) for dx in range(-2, 3)) / 25.0
    noise = noise[4:-4, 4:-4]
    noise = (noise - noise.min()) / (noise.max() - noise.min())
    return (noise * 255).astype(np.uint8)


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    """A Middlebury-like pair: a textured scene, frame 1 = frame 0 shifted by (u, v) = (2, 1),
    and its ground truth."""
    d = tmp_path_factory.mktemp("pair")
    big = texture(140, 180)
    a = big[10:130, 10:170]
    b = big[9:129, 8:168]  # b(x, y) = a(x - 2, y - 1): content moves right 2, down 1
    truth = np.zeros(a.shape + (2,), np.float32)
    truth[..., 0] = 2.0
    truth[..., 1] = 1.0
    write_pgm(d / "a.pgm", a)
    write_pgm(d / "b.pgm", b)
    roiflow.write_flo(str(d / "gt.flo"), truth)
    return d


def cli(*args, check=True):
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"roiflow {args} failed: {r.stderr}")
    return r


def cli_epe(stdout):
    m = re.search(r"EPE ([0-9.]+) px", stdout)
    assert m, stdout
    return float(m.group(1))


def epe(flow, truth):
    return float(np.mean(np.hypot(flow[..., 0] - truth[..., 0], flow[..., 1] - truth[..., 1])))


@pytest.mark.parametrize("preset", ["paper", "accurate", "fast"])
def test_dense_flow_equals_cli(pair, preset):
    out = cli("flow", pair / "a.pgm", pair / "b.pgm", "-o", pair / f"cli_{preset}.flo",
              "--gt", pair / "gt.flo", "--preset", preset)
    a = roiflow.read_gray(str(pair / "a.pgm"))
    b = roiflow.read_gray(str(pair / "b.pgm"))
    flow = roiflow.dense_flow(a, b, preset=preset)
    assert flow.shape == a.shape + (2,) and flow.dtype == np.float32
    cli_flow = roiflow.read_flo(str(pair / f"cli_{preset}.flo"))
    truth = roiflow.read_flo(str(pair / "gt.flo"))
    assert abs(epe(flow, truth) - epe(cli_flow, truth)) <= 1e-6
    assert np.array_equal(flow, cli_flow)
    errors = roiflow.flow_errors(flow, truth)
    assert abs(errors["epe"] - cli_epe(out.stdout)) <= 5e-5  # the CLI prints 4 decimals
    assert errors["epe"] < 0.5  # and the flow is right: (2, 1) everywhere


def test_dense_flow_overrides_equal_cli(pair):
    cli("flow", pair / "a.pgm", pair / "b.pgm", "-o", pair / "cli_o.flo", "--patch", 7,
        "--iterations", 5, "--levels", 2, "--derivative", "scharr", "--lambda", "1e-4")
    a = roiflow.read_gray(str(pair / "a.pgm"))
    b = roiflow.read_gray(str(pair / "b.pgm"))
    flow = roiflow.dense_flow(a, b, patch=7, iterations=5, levels=2, derivative="scharr",
                              lambda_=1e-4, threads=2)
    assert np.array_equal(flow, roiflow.read_flo(str(pair / "cli_o.flo")))
    default = roiflow.dense_flow(a, b)
    assert not np.array_equal(flow, default)  # the overrides did change something


@pytest.mark.skipif(not (DATA and os.path.isdir(os.path.join(DATA, "middlebury", "Grove2"))),
                    reason="../shared/data/middlebury/Grove2 absent")
def test_middlebury_grove2_epe_equals_cli(tmp_path):
    d = os.path.join(DATA, "middlebury", "Grove2")
    a_path, b_path, gt = (os.path.join(d, f) for f in ("frame10.png", "frame11.png", "flow10.flo"))
    out = cli("flow", a_path, b_path, "-o", tmp_path / "cli.flo", "--gt", gt)
    flow = roiflow.dense_flow(roiflow.read_gray(a_path), roiflow.read_gray(b_path))
    truth = roiflow.read_flo(gt)
    cli_flow = roiflow.read_flo(str(tmp_path / "cli.flo"))
    ours = roiflow.flow_errors(flow, truth)["epe"]
    assert abs(ours - roiflow.flow_errors(cli_flow, truth)["epe"]) <= 1e-6
    assert abs(ours - cli_epe(out.stdout)) <= 5e-5
    assert np.array_equal(flow, cli_flow)


def test_zero_copy_views_and_out(pair):
    a = roiflow.read_gray(str(pair / "a.pgm"))
    b = roiflow.read_gray(str(pair / "b.pgm"))
    # A column slice keeps packed rows with a longer row stride: read in place.
    va, vb = a[:, 8:], b[:, 8:]
    assert not va.flags["C_CONTIGUOUS"]
    flow_view = roiflow.dense_flow(va, vb)
    flow_copy = roiflow.dense_flow(np.ascontiguousarray(va), np.ascontiguousarray(vb))
    assert np.array_equal(flow_view, flow_copy)
    # A strided view (every other column) is copied, with the same answer.
    sa, sb = a[:, ::2], b[:, ::2]
    assert np.array_equal(roiflow.dense_flow(sa, sb),
                          roiflow.dense_flow(np.ascontiguousarray(sa), np.ascontiguousarray(sb)))
    # The result is written into `out` in place.
    out = np.full(a.shape + (2,), np.nan, np.float32)
    result = roiflow.dense_flow(a, b, out=out)
    assert np.shares_memory(result, out)
    assert np.array_equal(out, roiflow.dense_flow(a, b))
    # float32 in [0, 1] and BGR frames are accepted
    f = roiflow.dense_flow(a.astype(np.float32) / 255, b.astype(np.float32) / 255)
    assert f.shape == a.shape + (2,)
    bgr = roiflow.dense_flow(np.dstack([a] * 3), np.dstack([b] * 3))
    assert np.array_equal(bgr, roiflow.dense_flow(a, b))


def test_threads_run_concurrently(pair):
    a = roiflow.read_gray(str(pair / "a.pgm"))
    b = roiflow.read_gray(str(pair / "b.pgm"))
    expected = roiflow.dense_flow(a, b)
    results = [None] * 4

    def work(i):
        results[i] = roiflow.dense_flow(a, b)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert np.array_equal(r, expected)


def test_bad_arguments_raise_cli_messages(pair, tmp_path):
    a = roiflow.read_gray(str(pair / "a.pgm"))
    b = roiflow.read_gray(str(pair / "b.pgm"))
    with pytest.raises(roiflow.Error, match="patch"):
        roiflow.dense_flow(a, b, patch=2)
    with pytest.raises(roiflow.Error) as e:  # the library's check, as the CLI reports it
        roiflow.dense_flow(a, b, lambda_=2.0)
    r = cli("flow", pair / "a.pgm", pair / "b.pgm", "-o", tmp_path / "x.flo", "--lambda", 2,
            check=False)
    assert r.returncode != 0 and str(e.value) in r.stderr
    assert "\n" not in str(e.value)
    with pytest.raises(roiflow.Error, match="nope"):
        roiflow.dense_flow(a, b, preset="nope")
    with pytest.raises(roiflow.Error) as e:
        roiflow.read_flo(str(tmp_path / "missing.flo"))
    r = cli("flow", pair / "a.pgm", pair / "b.pgm", "-o", tmp_path / "y.flo", "--gt",
            tmp_path / "missing.flo", check=False)
    assert r.returncode != 0 and str(e.value) in r.stderr
    assert issubclass(roiflow.Error, ValueError)
    with pytest.raises(roiflow.Error):
        roiflow.dense_flow(a, b[:-1])
    with pytest.raises(TypeError):
        roiflow.dense_flow(a.astype(np.int64), b.astype(np.int64))
    with pytest.raises(TypeError):
        roiflow.dense_flow(a, b, patchh=7)
    with pytest.raises(TypeError):
        roiflow.dense_flow(a, b, patch=7.5)
    with pytest.raises(TypeError):
        roiflow.dense_flow(a[None], b[None])
    with pytest.raises(roiflow.Error):
        roiflow.dense_flow(a[:4, :4], b[:4, :4])  # below the smallest frame
    with pytest.raises(roiflow.Error):
        roiflow.dense_flow(a, b, threads=0)
    with pytest.raises(roiflow.Error):
        roiflow.dense_flow(a, b, out=np.zeros((3, 3, 2), np.float32))
    with pytest.raises(TypeError):
        roiflow.write_flo(str(tmp_path / "z.flo"), np.zeros((4, 4, 3), np.float32))
    with pytest.raises(roiflow.Error):
        roiflow.Tracker(init=(1, 2, 3))
    with pytest.raises(roiflow.Error):
        roiflow.Tracker(mode="sideways")
    with pytest.raises(roiflow.Error):
        roiflow.Tracker(roi=2)
    with pytest.raises(roiflow.Error, match="threads"):
        roiflow.Tracker(threads=0)
    with pytest.raises(roiflow.Error):
        roiflow.track(str(tmp_path / "missing.avi"))


def test_flo_roundtrip_and_color(tmp_path):
    rng = np.random.default_rng(3)
    flow = rng.normal(size=(17, 23, 2)).astype(np.float32)
    roiflow.write_flo(str(tmp_path / "f.flo"), flow)
    assert np.array_equal(roiflow.read_flo(str(tmp_path / "f.flo")), flow)
    color = roiflow.flow_to_color(flow)
    assert color.shape == (17, 23, 3) and color.dtype == np.uint8
    still = roiflow.flow_to_color(np.zeros((5, 5, 2), np.float32))
    assert (still == 255).all()  # no motion is white in the Middlebury wheel
    right = np.zeros((5, 5, 2), np.float32)
    right[..., 0] = 1
    assert not (roiflow.flow_to_color(right) == 255).all()


def square_frames(n, boxes, velocities, size=(160, 200)):
    """Bright textured squares moving on a darker texture, with their true boxes."""
    background = (texture(*size, seed=5) // 3).astype(np.uint8)
    patch = texture(40, 40, seed=7) // 2 + 120
    frames, truth = [], []
    for t in range(n):
        f = background.copy()
        boxes_t = []
        for (x, y, w, h), (vx, vy) in zip(boxes, velocities):
            x0, y0 = int(round(x + vx * t)), int(round(y + vy * t))
            f[y0:y0 + h, x0:x0 + w] = patch[:h, :w]
            boxes_t.append((x0, y0, w, h))
        frames.append(f)
        truth.append(boxes_t)
    return frames, truth


def test_tracker_follows_init_boxes():
    boxes = [(20, 30, 24, 24), (140, 100, 20, 20)]
    velocities = [(2, 1), (-2, -1)]
    frames, truth = square_frames(20, boxes, velocities)
    tracker = roiflow.Tracker(init=boxes)
    for i, f in enumerate(frames):
        objects = tracker.update(np.dstack([f] * 3) if i == 0 else f)  # BGR or gray
        assert [o.id for o in objects] == [1, 2]
    for o, (x, y, w, h) in zip(objects, truth[-1]):
        assert abs(o.box[0] - x) < 2 and abs(o.box[1] - y) < 2, (o, truth[-1])
        assert not o.lost and o.mode == "local"
    assert tracker.frames == 20
    assert abs(objects[0].velocity[0] - 2) < 0.5 and abs(objects[1].velocity[0] + 2) < 0.5
    one = roiflow.Tracker(init=boxes[0])
    assert [o.id for o in one.update(frames[0])] == [1]
    with pytest.raises(roiflow.Error):
        one.update(frames[1][:-8])  # another size than the first frame's


def test_track_iterator_equals_cli_log(tmp_path):
    source = "synthetic:40:320x240"
    log = tmp_path / "t.csv"
    cli("track", source, "--single", "--log", log, "--no-progress")
    rows = open(log).read().splitlines()[1:]
    assert len(rows) == 40
    seen = 0
    for (index, objects), row in zip(roiflow.track(source), rows):
        fields = row.split(",")
        assert int(fields[0]) == index + 1
        if objects:
            o = objects[0]
            assert o.id == 1
            assert [f"{v:.2f}" for v in o.box] == fields[2:6], (index, o, row)
            assert o.mode == fields[8] and int(o.lost) == int(fields[9])
            seen += 1
        else:
            assert fields[9] == "1"  # no target yet: logged as lost
    assert seen > 20  # the moving vehicle was found and followed
    it = roiflow.track(source, max_frames=5)
    assert it.size == (320, 240)
    assert len(list(it)) == 5
