"""What the seed-by-seed benchmarks of the tools (compare_benchmark.py,
check_benchmark.py) share: running a tool, the --seeds range, and their
command line with its work folder."""
import argparse
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent


def run(cmd, allowed=(0,)):
    """Runs cmd; any exit code outside `allowed` ends the benchmark with its output."""
    done = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if done.returncode not in allowed:
        sys.exit(f"{' '.join(map(str, cmd))} failed ({done.returncode}):\n{done.stdout[-1500:]}{done.stderr[-2500:]}")
    return done


def seeds(text):
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def parse_args(prefix, extra=None):
    """--build, --seeds, --work (kept; else a temporary folder, args.scratch), --pipeline-arg, --check;
    extra(parser) adds a benchmark's own."""
    parser = argparse.ArgumentParser()
    if extra:
        extra(parser)
    parser.add_argument("--build", type=pathlib.Path, default=ROOT / "build")
    parser.add_argument("--seeds", default="1-10")
    parser.add_argument("--work", type=pathlib.Path)
    parser.add_argument("--pipeline-arg", action="append", default=[])
    parser.add_argument("--check", action="store_true", help="exit 1 when a target is missed")
    args = parser.parse_args()
    args.build = args.build.resolve()
    args.scratch = args.work is None  # removed at the end; a --work folder is kept
    args.work = (args.work or pathlib.Path(tempfile.mkdtemp(prefix=prefix))).resolve()
    args.work.mkdir(parents=True, exist_ok=True)
    return args
