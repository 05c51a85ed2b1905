#!/usr/bin/env python3
"""Shards `roiflow batch` over a Dask distributed cluster: one task per video.

    scripts/dask_batch.py --scheduler tcp://10.0.0.5:8786 videos.txt --out /shared/out -- track
    scripts/dask_batch.py --scheduler tcp://127.0.0.1:8786 videos/ --out out -- dense --preset fast

Each task runs the per-video command `roiflow batch VIDEO --out OUT --no-csv --threads N --
JOB...` on a worker, so a video is done the way `roiflow batch` does it on one machine: its
folder OUT/<stem> is built under a partial name and renamed into place when complete, and a
video whose folder exists is skipped. That makes retries safe: a task whose worker dies is run
again elsewhere (the dead run's child process is killed with its worker, and its partial folder
removed by the next run on that host), and two runs of one video leave one folder. OUT must be
a folder every worker sees (a shared file system). When every task has ended, OUT/batch.csv
(video,status,frames,fps,seconds) is written from the folders' status.json, and the exit code is
1 when a video failed.

LIST is a folder of videos, a list file (.txt/.lst, one path a line, relative to the list's
folder, '#' comments), or one video: the same rule as `roiflow batch`.
"""
import argparse
import csv
import io
import json
import os
import shutil
import signal
import subprocess
import sys

VIDEO_EXTENSIONS = {".avi", ".mp4", ".mkv", ".mov", ".mpg", ".mpeg", ".m4v", ".webm", ".wmv",
                    ".flv", ".ts", ".mts"}


def batch_inputs(input_path):
    """The videos of LIST, as roiflow batch lists them (pipeline::batch_inputs)."""
    if os.path.isdir(input_path):
        videos = sorted(os.path.join(input_path, name) for name in os.listdir(input_path)
                        if os.path.isfile(os.path.join(input_path, name))
                        and os.path.splitext(name)[1].lower() in VIDEO_EXTENSIONS)
        if not videos:
            raise SystemExit(f"dask_batch: no video files in '{input_path}'")
        return videos
    if not os.path.exists(input_path):
        raise SystemExit(f"dask_batch: '{input_path}' does not exist")
    if os.path.splitext(input_path)[1].lower() not in (".txt", ".lst"):
        return [input_path]
    videos = []
    with open(input_path) as f:
        for line in f:
            line = line.rstrip("\r\n \t").lstrip(" \t")
            if not line or line.startswith("#"):
                continue
            videos.append(line if os.path.isabs(line)
                          else os.path.join(os.path.dirname(input_path), line))
    if not videos:
        raise SystemExit(f"dask_batch: the list '{input_path}' names no video")
    return videos


def stem(video):
    name = os.path.splitext(os.path.basename(video))[0]
    return name if name and not name.startswith(".") else "video" + name


def run_video(roiflow, video, out, threads, job):
    """One task: the per-video command on this worker. Its child dies with the worker."""
    import ctypes  # noqa: PLC0415 (runs on the worker)

    def die_with_worker():
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG

    r = subprocess.run([roiflow, "batch", video, "--out", out, "--no-csv", "--threads",
                        str(threads), "--", *job], capture_output=True, text=True,
                       preexec_fn=die_with_worker)
    return {"video": video, "returncode": r.returncode, "stdout": r.stdout,
            "stderr": r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""}


def alive(pid):
    """Whether process `pid` of this host runs (a zombie does not)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (OSError, IndexError):
        return False


def remove_dead_partials(out, stems):
    """Partial folders of this host's dead runs (a killed worker's child may die after the retry
    of its video has already checked): removed, as `roiflow batch` does when it starts."""
    import socket  # noqa: PLC0415

    host = socket.gethostname().replace(".", "_").replace("/", "_") or "host"
    for name in os.listdir(out):
        for s in stems:
            prefix = f".{s}.partial.{host}."
            pid = name[len(prefix):]
            if name.startswith(prefix) and pid.isdigit() and not alive(int(pid)):
                shutil.rmtree(os.path.join(out, name), ignore_errors=True)


def write_csv_atomically(path, rows):
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(["video", "status", "frames", "fps", "seconds"])
    for row in rows:
        writer.writerow(row)
    partial = os.path.join(os.path.dirname(path) or ".", "." + os.path.basename(path) + ".partial")
    with open(partial, "w") as f:
        f.write(text.getvalue())
    os.replace(partial, path)


def default_roiflow():
    here = os.path.dirname(os.path.abspath(__file__))
    built = os.path.join(here, "..", "build", "release", "roiflow")
    return os.path.abspath(built) if os.path.exists(built) else (shutil.which("roiflow") or
                                                               "roiflow")


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    job = []
    if "--" in argv:
        i = argv.index("--")
        argv, job = argv[:i], argv[i + 1:]
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scheduler", required=True, help="Dask scheduler address")
    parser.add_argument("list", metavar="LIST", help="folder of videos, list file or one video")
    parser.add_argument("--out", required=True, help="output folder every worker sees")
    parser.add_argument("--roiflow", default=default_roiflow(),
                        help="the roiflow binary on the workers (default: build/release/roiflow "
                             "beside this script, else roiflow on PATH)")
    parser.add_argument("--threads", type=int, default=1, help="threads of each task's run")
    parser.add_argument("--retries", type=int, default=2,
                        help="times a failed task is run again (a dead worker's task is "
                             "rescheduled by Dask regardless)")
    args = parser.parse_args(argv)
    if not job or job[0] not in ("track", "dense"):
        parser.error("give the job after '--': track|dense [options]")
    videos = batch_inputs(args.list)
    stems = {}
    for v in videos:
        if stem(v) in stems:
            raise SystemExit(f"dask_batch: '{stems[stem(v)]}' and '{v}' would share the output "
                             f"folder '{stem(v)}'; rename one")
        stems[stem(v)] = v
    os.makedirs(args.out, exist_ok=True)

    from distributed import Client, as_completed  # noqa: PLC0415 (only the driver needs it)

    results = {}
    with Client(args.scheduler) as client:
        futures = [client.submit(run_video, args.roiflow, v, args.out, args.threads, job,
                                 key=f"roiflow-batch-{i}-{stem(v)}", pure=False,
                                 retries=args.retries) for i, v in enumerate(videos)]
        for future in as_completed(futures):
            try:
                r = future.result()
            except Exception as e:  # noqa: BLE001 (a task that died too often)
                print(f"failed  task {future.key}: {e}", flush=True)
                continue
            results[r["video"]] = r
            word = "ended  " if r["returncode"] == 0 else "failed "
            print(f"{word} {r['video']}" + (f": {r['stderr']}" if r["returncode"] else ""),
                  flush=True)

    remove_dead_partials(args.out, stems)
    rows, failed = [], 0
    for v in videos:
        status_path = os.path.join(args.out, stem(v), "status.json")
        try:
            with open(status_path) as f:
                s = json.load(f)
            rows.append([v, s["status"], s["frames"], f"{s['fps']:.2f}", f"{s['seconds']:.3f}"])
        except (OSError, ValueError, KeyError):
            failed += 1
            why = results.get(v, {}).get("stderr", "") or "no result"
            rows.append([v, "failed: " + why.replace("roiflow: error: ", ""), 0, "0.00", "0.000"])
    csv_path = os.path.join(args.out, "batch.csv")
    write_csv_atomically(csv_path, rows)
    print(f"dask_batch: {len(videos)} videos, {len(videos) - failed} done, {failed} failed; "
          f"wrote {csv_path}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
