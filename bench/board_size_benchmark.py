#!/usr/bin/python3
"""The board's size by the depth sensor's own triangulation (issue 47: the
board's apparent size in depth against its size in colour), over randomized
sensors. stages/board_size_in_depth.h says how it is measured.

Per seed and scenario: a simulated session, calibrated with run-pipeline as a
user runs it, three times: with session.json's rig as recorded, and with its
square size typed 25 % too small and 25 % too large. The table gives what
report.json's depthboard_quads.board_size_in_depth measured against the truth
(the simulated sensor's own baseline), and whether run-pipeline warned.

The truth: the simulator draws the reciprocal model's a for the IR camera's
fx, so its sensor's baseline is B = -1 / (8 fx a); measured with the
family's 7.5 cm, a correctly described board reads 0.075 / B of its size.

Targets: the truth within the reported 3 sigma on >= 9 of 10 seeds per
scenario; no warning as recorded; a warning for both wrong sizes on every
seed.

usage (numpy and h5py: /usr/bin/python3):
  bench/board_size_benchmark.py --build build --seeds 1-10 [--work DIR] [--check]
"""
import glob
import json
import pathlib
import shutil
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
import calibration_benchmark as bench  # noqa: E402  (read_scenario)
import seed_bench  # noqa: E402
from seed_bench import run  # noqa: E402

SCENARIOS = {
    "user room": ROOT / "bench" / "speed_user_20poses.json",
    "stock": ROOT / "examples" / "scenarios" / "random_stock.json",
    "wide": ROOT / "examples" / "scenarios" / "random_wide_angle.json",
}
WRONG = {"as recorded": 1.0, "0.75x": 0.75, "1.25x": 1.25}
WARNING = "the depth sensor measures the board"


def expected_ratio(session):
    scenario = bench.read_scenario(session)
    model = scenario["depth_model"]
    if model["form"] != "reciprocal":
        return None
    fx = bench.true_ir_intrinsics(scenario)[0]
    return 0.075 / (-1 / (8 * fx * model["a"]))


def with_square_size(session, factor):
    manifest_path = session / "session.json"
    manifest = json.loads(manifest_path.read_text())
    manifest["rig"]["square_size_m"] *= factor
    manifest_path.write_text(json.dumps(manifest, indent=2))


def calibrate(args, session):
    done = run([args.build / "run-pipeline", session, "--new-version"], allowed=(0, 3))
    report = json.loads(pathlib.Path(sorted(glob.glob(str(session / "calibrations" / "v*" / "report.json")))[-1]).read_text())
    return report["depthboard_quads"]["board_size_in_depth"], WARNING in done.stdout + done.stderr


def one(args, name, scenario, seed):
    session = args.work / f"{name.replace(' ', '_')}-{seed}"
    shutil.rmtree(session, ignore_errors=True)
    run([args.build / "record-session", "sim", "--scenario", scenario, "--seed", seed, "--out", session])
    truth = expected_ratio(session)
    row = {"scenario": name, "seed": seed, "truth": truth}
    applied = 1.0
    for label, factor in WRONG.items():
        with_square_size(session, factor / applied)
        applied = factor
        measured, warned = calibrate(args, session)
        row[label] = {"measured": measured, "warned": warned}
    if args.scratch:
        shutil.rmtree(session, ignore_errors=True)
    return row


def cell(entry, truth, factor):
    m = entry["measured"]
    if m is None:
        return "not measured"
    z = (m["ratio"] - truth / factor) / (m["sigma_m"] / m["stated_m"]) if truth else float("nan")
    return f"{m['ratio']:.4f} +- {m['sigma_m'] / m['stated_m']:.4f} ({z:+.1f} sigma){' WARNED' if entry['warned'] else ''}"


def main():
    args = seed_bench.parse_args("board_size_")
    rows = []
    print("| scenario | seed | truth | " + " | ".join(WRONG) + " |")
    print("|---|---|---|" + "---|" * len(WRONG))
    for name, scenario in SCENARIOS.items():
        for seed in seed_bench.seeds(args.seeds):
            row = one(args, name, scenario, seed)
            rows.append(row)
            cells = [cell(row[label], row["truth"], factor) for label, factor in WRONG.items()]
            print(f"| {name} | {seed} | {row['truth']:.4f} | " + " | ".join(cells) + " |", flush=True)
    missed = summarize(rows)
    if args.scratch:
        shutil.rmtree(args.work, ignore_errors=True)
    sys.exit(1 if args.check and missed else 0)


def summarize(rows):
    missed = False
    for name in SCENARIOS:
        mine = [r for r in rows if r["scenario"] == name]
        m = [r["as recorded"]["measured"] for r in mine]
        within = sum(
            1 for r, x in zip(mine, m) if x and abs(x["ratio"] - r["truth"]) <= 3 * x["sigma_m"] / x["stated_m"])
        quiet = sum(1 for r in mine if not r["as recorded"]["warned"])
        caught = sum(1 for r in mine if r["0.75x"]["warned"] and r["1.25x"]["warned"])
        print(f"{name}: truth within 3 sigma {within}/{len(mine)}; no warning as recorded {quiet}/{len(mine)}; "
              f"both wrong sizes warned {caught}/{len(mine)}")
        missed |= within < 0.9 * len(mine) or quiet < len(mine) or caught < len(mine)
    return missed


if __name__ == "__main__":
    main()
