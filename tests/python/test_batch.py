"""roiflow batch (kill and resume, idempotence, failures) and scripts/dask_batch.py on a real
Dask scheduler with two worker processes on loopback, one of them killed mid-batch.

Run by ctest with ROIFLOW_CLI (the roiflow binary) and ROIFLOW_SOURCE_DIR.
"""
import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest

CLI = os.environ.get("ROIFLOW_CLI", "roiflow")
SOURCE = os.environ.get("ROIFLOW_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def cli(*args, check=True):
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"roiflow {args}: {r.stderr}")
    return r


@pytest.fixture(scope="module")
def videos(tmp_path_factory):
    """Three small videos of the synthetic scene (roiflow track's annotated output), in a list."""
    d = tmp_path_factory.mktemp("videos")
    paths = []
    for i, frames in enumerate((300, 300, 300)):
        p = d / f"clip{i}.avi"
        cli("track", f"synthetic:{frames}:320x240", "--single", "--out", p, "--no-progress",
            "--max-frames", frames - 10 * i)
        paths.append(p)
    (d / "list.txt").write_text("# three clips\n" + "".join(f"{p.name}\n" for p in paths))
    return d


def finished(out):
    return sorted(p.name for p in out.iterdir() if p.is_dir() and not p.name.startswith("."))


def partials(out):
    return sorted(p.name for p in out.iterdir() if ".partial." in p.name)


def check_complete(folder):
    """A finished folder: status.json done, and a track log with one row per frame."""
    status = json.loads((folder / "status.json").read_text())
    assert status["status"] == "done"
    rows = (folder / "track.csv").read_text().splitlines()
    assert rows[0] == "frame,id,x,y,w,h,vx,vy,mode,lost,ms"
    assert len(rows) == status["frames"] + 1
    assert [int(r.split(",")[0]) for r in rows[1:]] == list(range(1, status["frames"] + 1))
    return status


def read_batch_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_batch_kill_and_resume(videos, tmp_path):
    out = tmp_path / "out"
    listing = videos / "list.txt"
    # One video at a time; SIGKILL as soon as the first one is in place.
    p = subprocess.Popen([CLI, "batch", listing, "--out", out, "--threads", "1", "--", "track"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while time.time() < deadline and p.poll() is None:
        if out.exists() and finished(out):
            break
        time.sleep(0.002)
    p.send_signal(signal.SIGKILL)
    p.wait()
    done_before = finished(out)
    assert 1 <= len(done_before) < 3, done_before  # killed mid-batch
    for name in done_before:
        check_complete(out / name)
    first_log = out / done_before[0] / "track.csv"
    first_stat = first_log.stat()

    r = cli("batch", listing, "--out", out, "--", "track")
    words = [line.split()[0] for line in r.stdout.splitlines()[:-1]]
    assert sorted(words) == ["done"] * (3 - len(done_before)) + ["skipped"] * len(done_before)
    assert finished(out) == ["clip0", "clip1", "clip2"]
    assert partials(out) == []  # the killed run's partial folder is gone
    statuses = [check_complete(out / f"clip{i}") for i in range(3)]
    assert [s["frames"] for s in statuses] == [300, 290, 280]
    st = first_log.stat()
    assert (st.st_ino, st.st_mtime_ns) == (first_stat.st_ino, first_stat.st_mtime_ns)  # untouched
    rows = read_batch_csv(out / "batch.csv")
    assert [r["status"] for r in rows] == ["done"] * 3
    assert [int(r["frames"]) for r in rows] == [300, 290, 280]
    assert all(float(r["fps"]) > 0 and float(r["seconds"]) > 0 for r in rows)

    # The same as roiflow track's log (ms aside).
    cli("track", videos / "clip1.avi", "--single", "--log", tmp_path / "cli.csv", "--no-progress")
    strip = lambda text: [",".join(line.split(",")[:9]) for line in text.splitlines()]  # noqa: E731
    assert strip((out / "clip1" / "track.csv").read_text()) == strip((tmp_path / "cli.csv").read_text())

    # A third run does no work and reports every video done.
    r = cli("batch", listing, "--out", out, "--", "track")
    assert r.stdout.count("skipped") == 3 and "0 run, 3 already done" in r.stdout
    assert [r["status"] for r in read_batch_csv(out / "batch.csv")] == ["done"] * 3


def test_batch_dense_and_failures(videos, tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    (d / "broken.avi").write_text("not a video\n")
    os.symlink(videos / "clip2.avi", d / "clip2.avi")
    out = tmp_path / "out"
    r = cli("batch", d, "--out", out, "--max-frames", 12, "--", "dense", "--preset", "fast",
            check=False)
    assert r.returncode == 1
    assert "1 of 2 videos failed" in r.stderr
    rows = read_batch_csv(out / "batch.csv")
    assert [row["video"].endswith(n) for row, n in zip(rows, ["broken.avi", "clip2.avi"])] == [True] * 2
    assert rows[0]["status"].startswith("failed: ") and "broken.avi" in rows[0]["status"]
    assert rows[1]["status"] == "done" and int(rows[1]["frames"]) == 12
    assert finished(out) == ["clip2"] and (out / "clip2" / "flow.avi").stat().st_size > 0
    assert partials(out) == []
    # a rerun retries the failed video only
    r = cli("batch", d, "--out", out, "--", "dense", check=False)
    assert r.returncode == 1 and "skipped" in r.stdout
    assert sorted(line.split()[0] for line in r.stdout.splitlines()[:-1]) == ["failed", "skipped"]
    # bad command lines
    for args, message in [((d, "--out", out, "--", "walk"), "must be track or dense"),
                          ((d, "--out", out), "needs a job"),
                          ((d, "--out", out, "--", "track", "--roi", "2"), "--roi"),
                          ((tmp_path / "none", "--out", out, "--", "track"), "does not exist")]:
        r = cli("batch", *args, check=False)
        assert r.returncode != 0 and message in r.stderr, (args, r.stderr)
        assert r.stderr.count("\n") == 1
    (tmp_path / "dup.txt").write_text(f"{videos / 'clip0.avi'}\n{d / 'clip2.avi'}\n"
                                      f"{videos / 'clip2.avi'}\n")
    r = cli("batch", tmp_path / "dup.txt", "--out", out, "--", "track", check=False)
    assert r.returncode != 0 and "share the output folder 'clip2'" in r.stderr


def test_dask_batch_with_a_killed_worker(videos, tmp_path):
    distributed = pytest.importorskip("distributed")
    out = tmp_path / "out"
    script = os.path.join(SOURCE, "scripts", "dask_batch.py")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None,
                                  silence_logs=50) as cluster, \
            distributed.Client(cluster) as client:
        p = subprocess.Popen([sys.executable, script, "--scheduler", cluster.scheduler_address,
                              videos / "list.txt", "--out", out, "--roiflow", CLI, "--", "track"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # Kill a worker process (SIGKILL) while it runs a video: its task is run again.
        deadline = time.time() + 120
        while time.time() < deadline and p.poll() is None:
            if out.exists() and partials(out):
                break
            time.sleep(0.002)
        running = [name for name in partials(out)] if out.exists() else []
        pids = client.run(os.getpid)
        victim = sorted(pids.values())[0]
        os.kill(victim, signal.SIGKILL)
        stdout, stderr = p.communicate(timeout=240)
    assert running, "no video was running when the worker was killed"
    assert p.returncode == 0, stdout + stderr
    assert "3 done, 0 failed" in stdout
    assert finished(out) == ["clip0", "clip1", "clip2"]
    assert partials(out) == []
    frames = [check_complete(out / f"clip{i}")["frames"] for i in range(3)]
    assert frames == [300, 290, 280]
    rows = read_batch_csv(out / "batch.csv")
    assert [os.path.basename(r["video"]) for r in rows] == ["clip0.avi", "clip1.avi", "clip2.avi"]
    assert [r["status"] for r in rows] == ["done"] * 3
