#!/usr/bin/python3
"""Wide-angle room benchmark: wall segmentation and the undistortion grid in
rooms whose floor, ceiling and furniture enter the wide view.

Per seed it records a randomized wide-angle room session
(examples/scenarios/random_wide_room.json: billowing adapter, 30-40 wall
snapshots from 0.5 to 3 m, walls up to 2 degrees off square, floor, ceiling
and furniture drawn per session), gives the pipeline the true camera
intrinsics in session.json (as a user with calibrated cameras would; with
--cameras-from-outlines it does not, and the depth camera comes from the
depthboard outlines and board planes, as for a user without an IR
chessboard recording), calibrates it (run-pipeline) and compares with the
truth the session stores:

  paired      board frames paired / board frames (calibration.json metrics)

  room        far snapshots (beyond mid-range) whose true view holds floor,
              ceiling or furniture on more than 1 % of the valid pixels
  kept        wall snapshots the planar stage kept / recorded
  sigma_red   held-out flat-wall sigma reduction by the grid (report.json
              undistortion.wall_sigma_reduction_held_out)
  floor_x     board model's held-out RMS over its noise floor
              (report.json diagnosis.ratio_to_floor), chosen model
  model       the chosen model; "+undistortion" when the grid is used
  depth_err   max |model depth - true depth| / true depth at the image
              centre over 0.6-3 m (calibration_benchmark.depth_error)
  tilt_err    largest |measured - true| tilt of a kept wall (degrees): the
              stage's tilt (report.json tilt_deg) against the simulated wall's
  ext_dz      colour-to-depth translation along the depth axis, fitted minus
              true (mm): the board poses' depth, which the walls do not touch,
              rides on it
  iou min/med wall mask (report.json planar_snapshots[].wall_mask) against
              the simulator's true wall (bench/sim_wall_truth) on the same
              sampled pixels, both limited to pixels with a reading

Usage (numpy, h5py, opencv: run with /usr/bin/python3):
  bench/room_benchmark.py --seeds 1-10 [--check]

With --check, exits 1 when any seed misses an acceptance (sigma: reduction
>= 80 %; floor: board model <= 1.3x the floor; depth: within 0.5 %; iou:
every kept snapshot's IoU >= 0.95); --check iou,sigma checks only those.
Without it, exits 0 whenever the runs happened.
"""
import argparse
import dataclasses
import json
import math
import pathlib
import shutil
import sys
import tempfile

import cv2
import h5py
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import calibration_benchmark as cb  # noqa: E402  (the truth and calibration readers)

SCENARIO = pathlib.Path(__file__).resolve().parent.parent / "examples" / "scenarios" / "random_wide_room.json"
DEPTH_RANGE_M = (0.6, 3.0)
MIN_SIGMA_REDUCTION, MAX_FLOOR_RATIO, MAX_DEPTH_ERROR, MIN_IOU = 0.80, 1.3, 0.005, 0.95


@dataclasses.dataclass
class Row:
    seed: int
    failure: str = ""
    far: int = 0
    far_with_room: int = 0
    kept: int = 0
    snapshots: int = 0
    sigma_reduction: float = math.nan
    floor_ratio: float = math.nan
    model: str = ""
    depth_error: float = math.nan
    ious: list = dataclasses.field(default_factory=list)
    tilt_error_deg: float = math.nan
    extrinsic_dz_mm: float = math.nan
    rejections: dict = dataclasses.field(default_factory=dict)
    paired: int = 0
    board_frames: int = 0


def decode_mask(mask):
    runs = np.asarray(mask["runs"], dtype=int)
    values = np.zeros(len(runs), dtype=np.uint8)
    values[1::2] = 1
    return np.repeat(values, runs).reshape(mask["rows"], mask["cols"]).astype(bool)


def mask_agreement(session, report, truth_dir, row):
    """IoU of each kept snapshot's mask with the truth, on its sampled grid."""
    scenario = cb.read_scenario(session)
    planar = scenario["planar"]
    middle = (planar["min_depth_m"] + planar["max_depth_m"]) / 2
    with h5py.File(session / "planar.h5", "r") as f:
        frames = f["depth/frames"]
        poses = np.asarray(f["truth/ir_from_target_at_depth"]).reshape(-1, 4, 4)
        depth_z = poses[:, 2, 3]
        true_tilt = np.degrees(np.arccos(np.clip(np.abs(poses[:, 2, 2]), 0, 1)))
        row.snapshots = frames.shape[0]
        for index in range(frames.shape[0]):
            truth = cv2.imread(str(truth_dir / f"{index:06d}.png"), cv2.IMREAD_GRAYSCALE) > 0
            valid = np.asarray(frames[index]) != 2047
            if depth_z[index] > middle:
                row.far += 1
                intruders = valid & ~truth
                row.far_with_room += int(intruders.sum() > 0.01 * valid.sum())
        kept = {s["frame"]: s for s in report["planar_snapshots"]}
        row.kept = len(kept)
        if kept:
            row.tilt_error_deg = max(abs(s["tilt_deg"] - true_tilt[i]) for i, s in kept.items())
        for index, snap in kept.items():
            m = snap["wall_mask"]
            found = decode_mask(m)
            rows = m["crop_px"] + m["stride"] * np.arange(m["rows"])
            cols = m["crop_px"] + m["stride"] * np.arange(m["cols"])
            truth = cv2.imread(str(truth_dir / f"{index:06d}.png"), cv2.IMREAD_GRAYSCALE)[np.ix_(rows, cols)] > 0
            valid = np.asarray(frames[index])[np.ix_(rows, cols)] != 2047
            truth &= valid
            union = (found | truth).sum()
            row.ious.append(float((found & truth).sum() / union) if union else math.nan)
    for frame in report["frames"]:
        if frame.get("recording") == "planar" and "reason" in frame:
            row.rejections[frame["reason"]] = row.rejections.get(frame["reason"], 0) + 1


def extrinsic_dz_mm(calibration, scenario):
    """Fitted minus true depth_from_colour translation z (mm)."""
    cameras = scenario["cameras"]
    rotation = cv2.Rodrigues(np.radians(np.asarray(cameras["colour_from_ir_rotation_deg"], dtype=float)))[0]
    true_t = -rotation.T @ np.asarray(cameras["colour_from_ir_m"], dtype=float)
    return 1000 * (calibration["cameras"]["depth_from_colour"]["translation_m"][2] - true_t[2])


def evaluate(session, row, truth_dir):
    scenario = cb.read_scenario(session)
    version = cb.newest_version(session)
    calibration = json.loads((version / "calibration.json").read_text())
    report = json.loads((version / "report.json").read_text())
    undistortion = report.get("undistortion", {})
    if "wall_sigma_reduction_held_out" in undistortion:
        row.sigma_reduction = undistortion["wall_sigma_reduction_held_out"]
    row.floor_ratio = report["diagnosis"]["ratio_to_floor"]
    row.model = calibration["model"]["name"]
    row.paired, row.board_frames = int(calibration["metrics"]["paired_frames"]), int(calibration["metrics"]["board_frames"])
    row.depth_error, _ = cb.depth_error(calibration, version, scenario, DEPTH_RANGE_M, report)
    row.extrinsic_dz_mm = extrinsic_dz_mm(calibration, scenario)
    mask_agreement(session, report, truth_dir, row)


def bench_seed(args, seed, out_dir):
    row = Row(seed)
    session = out_dir / f"room-seed{seed}"
    truth_dir = out_dir / f"room-seed{seed}-truth"
    for path in (session, truth_dir):
        if path.exists() and not args.reuse:
            shutil.rmtree(path)
    build = pathlib.Path(args.build)
    try:
        if not args.reuse:
            cb.run([str(build / "record-session"), "sim", "--scenario", str(args.scenario), "--seed", str(seed),
                    "--out", str(session)], "record-session")
            if not args.cameras_from_outlines:
                cb.give_true_cameras(session)
            cb.run([str(build / "bench" / "sim_wall_truth"), str(session), str(truth_dir)], "sim_wall_truth")
            cb.run([str(build / "run-pipeline"), str(session)], "run-pipeline")
        evaluate(session, row, truth_dir)
    except (RuntimeError, ValueError, KeyError, OSError) as e:
        row.failure = str(e) if not isinstance(e, KeyError) else f"missing key {e}"
    finally:
        if not args.keep and not args.reuse:
            for path in (session, truth_dir):
                shutil.rmtree(path, ignore_errors=True)
    return row


CHECKS = ("sigma", "floor", "depth", "iou")


def failures(row, checks=CHECKS):
    """The acceptances (of `checks`) a row misses, in words."""
    if row.failure:
        return ["failed"]
    missed = []
    if "sigma" in checks and not row.sigma_reduction >= MIN_SIGMA_REDUCTION:
        missed.append(f"sigma {-row.sigma_reduction:+.0%}")
    if "floor" in checks and not row.floor_ratio <= MAX_FLOOR_RATIO:
        missed.append(f"floor {row.floor_ratio:.2f}x")
    if "depth" in checks and not row.depth_error <= MAX_DEPTH_ERROR:
        missed.append(f"depth {row.depth_error:.2%}")
    if "iou" in checks and (not row.ious or not min(row.ious) >= MIN_IOU):
        missed.append(f"iou {min(row.ious) if row.ious else math.nan:.3f}")
    return missed


def parse_checks(text):
    checks = tuple(c for c in text.split(",") if c)
    unknown = [c for c in checks if c not in CHECKS]
    if unknown:
        raise argparse.ArgumentTypeError(f"--check: unknown {', '.join(unknown)} (known: {', '.join(CHECKS)})")
    return checks


HEADER = (f"{'seed':>4} {'paired':>7} {'room':>6} {'kept':>6} {'sigma_red':>9} {'floor_x':>7} {'depth_err':>9} "
          f"{'ext_dz':>6} {'tilt_err':>8} {'iou_min':>7} {'iou_med':>7} {'model':<26} verdict")


def format_row(row):
    if row.failure:
        return f"{row.seed:>4} failed: {row.failure}"
    missed = failures(row)
    ious = np.array(row.ious) if row.ious else np.array([math.nan])
    return (f"{row.seed:>4} {row.paired:>3}/{row.board_frames:<3} {row.far_with_room:>2}/{row.far:<3} {row.kept:>2}/{row.snapshots:<3} "
            f"{row.sigma_reduction:>9.1%} {row.floor_ratio:>7.2f} {row.depth_error:>9.3%} "
            f"{row.extrinsic_dz_mm:>+6.1f} {row.tilt_error_deg:>8.2f} {np.nanmin(ious):>7.3f} {np.nanmedian(ious):>7.3f} {row.model:<26} "
            + ("ok" if not missed else "; ".join(missed))
            + "".join(f"\n       rejected {n} x: {reason}" for reason, n in row.rejections.items()))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=cb.parse_seeds, default=cb.parse_seeds("1-10"), help="e.g. 1-10 or 1,4,7")
    parser.add_argument("--scenario", default=str(SCENARIO), help="randomized wide-angle room scenario")
    parser.add_argument("--out-dir", help="where sessions go (default: a temporary directory)")
    parser.add_argument("--keep", action="store_true", help="keep the sessions and truth masks")
    parser.add_argument("--reuse", action="store_true",
                        help="evaluate the sessions an earlier --keep run left in --out-dir again, without recording")
    parser.add_argument("--check", nargs="?", type=parse_checks, const=CHECKS, default=(),
                        help="exit 1 when any seed misses an acceptance (all, or e.g. iou,sigma)")
    parser.add_argument("--build", default="build", help="build directory holding record-session, run-pipeline")
    parser.add_argument("--cameras-from-outlines", action="store_true",
                        help="do not write the drawn cameras into session.json: the depth camera comes from the "
                             "depthboard outlines (a user without calibrated cameras)")
    args = parser.parse_args()
    out_dir = pathlib.Path(args.out_dir or tempfile.mkdtemp(prefix="speckle-room-"))
    out_dir.mkdir(parents=True, exist_ok=True)
    print(HEADER, flush=True)
    rows = []
    for seed in args.seeds:
        print(f"[room] seed {seed}: recording and calibrating", file=sys.stderr, flush=True)
        rows.append(bench_seed(args, seed, out_dir))
        print(format_row(rows[-1]), flush=True)
    passed = sum(1 for r in rows if not failures(r))
    print(f"summary: {len(rows)} seeds, {sum(1 for r in rows if r.failure)} failed, {passed} pass every acceptance",
          flush=True)
    if not args.out_dir and not args.keep:
        shutil.rmtree(out_dir, ignore_errors=True)
    return 1 if args.check and any(failures(r, args.check) for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
