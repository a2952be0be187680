#!/usr/bin/python3
"""Two or more builds of one tool, run in turn on the same arguments.

On this 2-core virtual machine the same binary's time moves by tens of per
cent within minutes, so a change is timed against the build before it in the
same run: each repeat runs every binary once, in turn, and the table gives
each one's median wall and user time. Copy each build's tool aside first
(the tools link our libraries statically):

  cp build/refit /tmp/refit-before        # then rebuild with the change
  bench/alternate_builds.py --repeats 3 --cwd /tmp/sb /tmp/refit-before build/refit \\
      -- herrera --from v0001 --model formula60.json

Each run's summary line starting with "residual" is printed beside its time,
so that a change in results shows too.
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import time


def main():
    argv = sys.argv[1:]
    if "--" not in argv:
        sys.exit("usage: alternate_builds.py [--repeats N] [--cwd DIR] BINARY... -- ARGUMENTS...")
    split = argv.index("--")
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--cwd", default=".")
    parser.add_argument("binaries", nargs="+")
    args = parser.parse_args(argv[:split])
    arguments = argv[split + 1:]
    times = {b: [] for b in args.binaries}
    for _ in range(args.repeats):
        for binary in args.binaries:
            before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
            start = time.perf_counter()
            done = subprocess.run([os.path.abspath(binary), *arguments], cwd=args.cwd, capture_output=True, text=True)
            wall = time.perf_counter() - start
            user = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
            if done.returncode != 0:
                sys.exit(f"{binary} exited {done.returncode}:\n{done.stderr[-2000:]}")
            residual = next((l for l in done.stdout.splitlines() if l.startswith("residual")), "")
            times[binary].append((wall, user))
            print(f"{binary}: {wall:.1f} s, user {user:.1f} s  {residual}", flush=True)
    print("\n| build | median wall s | median user s |\n|---|---|---|")
    for binary, runs in times.items():
        print(f"| {binary} | {statistics.median(w for w, _ in runs):.1f} | {statistics.median(u for _, u in runs):.1f} |")


if __name__ == "__main__":
    main()
