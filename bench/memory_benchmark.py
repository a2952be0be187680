#!/usr/bin/python3
"""run-pipeline's peak memory against the session's length.

Per size it records a stock simulated session of N depthboard frames (N/4
still poses of 4 frames; 16 wall snapshots; the thesis's IR chessboard
recording), runs run-pipeline on it twice in the same run -- once with its
default budget of held raw images, once holding none -- and prints the peak
resident set size (getrusage of the child) and the wall time of each:

  pairs        depthboard frames paired
  samples      paired samples
  peak_MB      run-pipeline's peak RSS with the default --held-raw-frames
  held0_MB     the same with --held-raw-frames 0 (every raw image read again)
  s / held0_s  wall time of each run

Usage (from the repository root, after a build):
  bench/memory_benchmark.py [--frames 200,2000] [--build build]
"""
import argparse
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent


def record(build, frames, folder):
    scenario = json.loads((ROOT / "examples" / "scenarios" / "stock.json").read_text())
    scenario["depthboard"]["poses"] = frames // 4
    scenario["depthboard"]["frames_per_pose"] = 4
    scenario["planar"]["snapshots"] = 16
    path = folder / "scenario.json"
    path.write_text(json.dumps(scenario))
    subprocess.run([str(build / "record-session"), "sim", "--scenario", str(path), "--out", str(folder / "s")],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return folder / "s"


def peak_run(build, session, extra):
    """(peak RSS in MB, seconds, stdout) of one run-pipeline child (os.wait4 gives that child's own rusage)."""
    start = time.monotonic()
    with tempfile.TemporaryFile("w+") as out:
        child = subprocess.Popen([str(build / "run-pipeline"), str(session), *extra], stdout=out,
                                 stderr=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        if child.returncode != 0:
            sys.exit(f"run-pipeline {session} {' '.join(extra)} exited {child.returncode}")
        out.seek(0)
        return usage.ru_maxrss / 1024.0, time.monotonic() - start, out.read()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--frames", default="200,2000")
    parser.add_argument("--build", default=str(ROOT / "build"))
    args = parser.parse_args()
    build = pathlib.Path(args.build)
    print(f"{'frames':>7} {'pairs':>6} {'samples':>8} {'peak_MB':>8} {'s':>6} {'held0_MB':>9} {'held0_s':>8}")
    for frames in sorted(int(f) for f in args.frames.split(",")):
        with tempfile.TemporaryDirectory() as tmp:
            session = record(build, frames, pathlib.Path(tmp))
            held0_mb, held0_s, _ = peak_run(build, session, ["--held-raw-frames", "0"])
            peak_mb, seconds, summary = peak_run(build, session, [])
            m = re.search(r"(\d+) of (\d+) depthboard frames paired, (\d+) samples", summary)
            pairs, samples = (m.group(1), m.group(3)) if m else ("?", "?")
            print(f"{frames:>7} {pairs:>6} {samples:>8} {peak_mb:>8.0f} {seconds:>6.1f} {held0_mb:>9.0f} {held0_s:>8.1f}",
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
