#!/usr/bin/python3
"""compare over randomized sensors (issue 48): two sessions of one sensor
agree within their uncertainty (3 sigma of their difference; the sum sigma A +
sigma B is what the maps draw), two sensors differ and compare says where.

Per seed: session A of a user-like simulated sensor (no IR recording, no
intrinsics given, 20 poses, a room), session B of the same sensor (A's drawn
scenario with another seed: other board poses, other noise), session C of
another sensor (the next draw). Each is calibrated with run-pipeline as a
user runs it, then `compare A B` and `compare A C`.

Targets: A and B "the same within their uncertainty" on >= 9 of 10 seeds;
A and C "differ" on every seed, with the region named. --power then compares
each A with copies of itself whose every depth is 0.1-1 % nearer (a table of
how many seeds each is found on; shown, not a target).

usage (numpy and h5py: /usr/bin/python3):
  bench/compare_benchmark.py --build build --seeds 1-10 [--work DIR] [--pipeline-arg=--separate-cameras] [--power] [--check]
"""
import json
import pathlib
import re
import shutil
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
import calibration_benchmark as bench  # noqa: E402  (read_scenario)
import seed_bench  # noqa: E402

SCENARIO = ROOT / "bench" / "speed_user_20poses.json"


def run(cmd):
    return seed_bench.run(cmd).stdout


def calibrated(args, name, *record_args):
    session = args.work / name
    shutil.rmtree(session, ignore_errors=True)
    run([args.build / "record-session", "sim", *record_args, "--out", session])
    run([args.build / "run-pipeline", session, *args.pipeline_arg])
    return session


def same_sensor_again(args, session, seed):
    """A's drawn scenario (its sensor, room and session shape) with another seed: other poses, other noise."""
    scenario = bench.read_scenario(session)
    scenario["seed"] = seed
    path = args.work / f"again-{seed}.json"
    path.write_text(json.dumps(scenario))
    return path


def verdict(text):
    line = next(l for l in text.splitlines() if l.startswith("verdict"))
    return line.split(None, 1)[1]


def one_seed(args, seed):
    a = calibrated(args, f"a-{seed}", "--scenario", SCENARIO, "--seed", seed)
    b = calibrated(args, f"b-{seed}", "--scenario", same_sensor_again(args, a, 10000 + seed))
    c = calibrated(args, f"c-{seed}", "--scenario", SCENARIO, "--seed", 1000 + seed)
    same, other = verdict(run([args.build / "compare", a, b])), verdict(run([args.build / "compare", a, c]))
    region = re.search(r"most in the (.+) of the image", other)
    return {"seed": seed, "same_sensor": same, "other_sensor": other,
            "same_ok": same.startswith("the same"), "other_ok": other.startswith("differ") and region is not None}


POWER_SCALES = (0.001, 0.002, 0.003, 0.005, 0.01)


def scaled_copy(args, version, scale):
    """A's newest version with every depth nearer by `scale`: 1/z = a r + b, its base form's a and b times 1 + scale."""
    copy = args.work / "power" / f"{version.parent.parent.name}-{scale}"
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(version, copy)
    calibration = json.loads((copy / "calibration.json").read_text())
    for p in calibration["model"]["parameters"]:
        if p["block"] == "base":
            p["value"] *= 1 + scale
    (copy / "calibration.json").write_text(json.dumps(calibration))
    return copy


def power(args, seeds):
    """How small a depth scale compare finds: each seed's A against copies of it scaled (the same sigmas)."""
    print("\n| every depth nearer by | judged different |\n|---|---|")
    for scale in POWER_SCALES:
        found = 0
        for seed in seeds:
            version = sorted((args.work / f"a-{seed}" / "calibrations").glob("v*"))[-1]
            found += verdict(run([args.build / "compare", version, scaled_copy(args, version, scale)])).startswith(
                "differ")
        print(f"| {100 * scale:.1f} % | {found} of {len(seeds)} |", flush=True)


def main():
    args = seed_bench.parse_args("compare-bench-", lambda parser: parser.add_argument(
        "--power", action="store_true", help="also compare each A with copies of it, every depth scaled"))
    rows = []
    print("| seed | same sensor, two sessions | two sensors |\n|---|---|---|", flush=True)
    for seed in seed_bench.seeds(args.seeds):
        row = one_seed(args, seed)
        rows.append(row)
        print(f"| {seed} | {row['same_sensor']} | {row['other_sensor']} |", flush=True)
    same = sum(r["same_ok"] for r in rows)
    other = sum(r["other_ok"] for r in rows)
    need_same = len(rows) - len(rows) // 10
    print(f"\nsame sensor judged the same: {same} of {len(rows)} (target >= {need_same}); "
          f"two sensors judged to differ, with where: {other} of {len(rows)} (target all)")
    if args.power:
        power(args, [r["seed"] for r in rows])
    if args.scratch:
        shutil.rmtree(args.work, ignore_errors=True)
    if args.check and (same < need_same or other < len(rows)):
        sys.exit(1)


main()
