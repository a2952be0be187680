#!/usr/bin/python3
"""Hunt benchmark: does the diagnosis find what a user-sized session hides?

Each row is one hidden effect; each seed draws a fresh sensor, room and
user-like session from examples/scenarios/random_stock.json (20 poses x 3
frames, 40 wall snapshots unless the effect says none, no IR recording),
hides the effect in it, runs run-pipeline, and when the diagnosis recommends
an effect runs the refit it suggests. As a user runs it (--cameras
estimated, the default) the session has colour and depth only: both cameras
come from the session. --cameras given writes the true intrinsics into
session.json first (a user with cameras calibrated elsewhere): the second
column, never instead of the first. Per effect over the seeds:

  first     seeds on which the right candidate (or, outside the catalogue,
            the right covariate) is the one the diagnosis names first
  <=1.15    seeds whose held-out RMS ends within 1.15x the noise floor after
            the recommended refit, and again while the verdict recommends
            another (--follow: 3 refits at most; the run's own ratio when
            nothing is recommended)
  recommends seeds on which anything is recommended
  ratio     median held-out / floor before -> after the refit (outside the
            catalogue: after refitting the formula effect the verdict suggests)

Targets (issue 18): first >= 9/10, <=1.15 >= 9/10, clean: recommends <= 1/10.

Usage (numpy/h5py: run with /usr/bin/python3):
  bench/hunt_benchmark.py --seeds 1-10                     # every effect
  bench/hunt_benchmark.py --effects raw_step,clean --seeds 1-3 --check
  bench/hunt_benchmark.py --cameras given --seeds 1-10     # the true intrinsics given

With --check, exits 1 when a row misses a target (over the seeds run); with
--check-first-only as well, only when the right answer is not ranked first
(and no refit is made).
"""
import argparse
import copy
import dataclasses
import json
import pathlib
import shutil
import statistics
import sys
import tempfile
import time

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from calibration_benchmark import give_true_cameras, newest_version, parse_seeds, read_scenario, run  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
BASE_SCENARIO = ROOT / "examples/scenarios/random_stock.json"


@dataclasses.dataclass
class Hidden:
    name: str
    overlay: dict          # merged into the base scenario
    right: tuple           # candidate names, or "covariate:<name>" for effects outside the catalogue
    walls: bool = True     # 40 wall snapshots (False: none)


# The hidden effects the issue lists, with the sizes it used.
HIDDEN = [
    Hidden("clean", {}, ()),
    Hidden("albedo_bias", {"effects": {"albedo_bias": {"dark_bias_raw": 4}}}, ("albedo_bias",)),
    Hidden("capture_time_offset",
           {"effects": {"capture_time_offset": {"offset_s": 0.033, "board_speed_m_s": 0.2}}},
           ("capture_time_offset",)),
    # With the cameras given, the joint calibration fits the depth image's
    # principal point (the camera given is the IR image's) and names the
    # shift there (depth_principal_point; see shift_in_principal_point).
    Hidden("depth_grid_offset", {"effects": {"depth_grid_offset": {"dx_px": 4, "dy_px": 3}}},
           ("depth_grid_offset", "depth_principal_point")),
    Hidden("thermal_drift", {"effects": {"thermal_drift": {"amplitude_raw": -6, "time_constant_s": 600}}},
           ("thermal_drift",)),
    # The same drift through an OpenNI-like driver's millimetres (random_stock_mm.json's conversion).
    Hidden("thermal_drift_mm",
           {"depth_model": {"a": -0.0027681, "b": 3.0163, "units": "millimetre", "mm_gain": 1.02, "mm_offset_m": 0.01},
            "effects": {"thermal_drift": {"amplitude_raw": -6, "time_constant_s": 600}}},
           ("thermal_drift_mm",)),
    Hidden("radial_billow", {"effects": {"radial_billow": {"bx_raw2": 60000, "by_raw2": 25000}}},
           ("radial_billow",), walls=False),
    Hidden("tangent_base", {"depth_model": {"form": "tangent", "c": 0.15257, "k": 2431.3, "b": 1.1200}},
           ("base_form:tangent",)),
    Hidden("raw_step", {"effects": {"raw_step": {"level_raw": 700, "height_raw": 2}}},
           ("covariate:raw", "covariate:depth")),
    # 3 raw, about 25 px correlation (26 cells across 640 px), no walls.
    Hidden("pixel_pattern",
           {"effects": {"disparity_pattern": {"amplitude_raw": 3, "decay_per_raw": 0.004, "cells": 26}}},
           ("disparity_pattern", "spatial_field"), walls=False),
    # A disparity offset linear over the image: the reference pattern's tilt,
    # or the smooth spatial field that also follows it.
    Hidden("linear_offset", {"effects": {"image_linear_offset": {"slope_x_raw": 8, "slope_y_raw": -5}}},
           ("reference_tilt", "spatial_field")),
]


def scenario_for(hidden, poses, frames, snapshots):
    base = json.loads(BASE_SCENARIO.read_text())
    s = copy.deepcopy(base)
    for key, value in hidden.overlay.items():
        if key == "depth_model":  # another form: its own parameters, the base's noise
            s["depth_model"] = dict(value, raw_noise_sigma=base["depth_model"]["raw_noise_sigma"])
        elif isinstance(value, dict):
            s.setdefault(key, {}).update(value)
        else:
            s[key] = value
    session = s["randomize"]["session"]
    session["poses"] = [poses, poses]
    session["frames_per_pose"] = [frames, frames]
    session["snapshots"] = [snapshots, snapshots] if hidden.walls else [0, 0]
    s["label"] = f"hunt benchmark: {hidden.name}"
    return s


@dataclasses.dataclass
class Row:
    effect: str
    seed: int
    named: str = ""          # what the diagnosis names first
    first_right: bool = False
    recommended: str = ""
    ratio_before: float = float("nan")
    ratio_after: float = float("nan")
    min_p: float = float("nan")    # the smallest pose-level p of a candidate cutting 3 % or more
    complete: bool = False
    refit: str = ""                # "formula" when the verdict's formula hint was refitted
    followed: list = dataclasses.field(default_factory=list)  # every refit the verdicts recommended, in order
    seconds: float = 0
    error: str = ""
    principal_point_shift: str = ""  # the fitted depth camera's cx, cy less the true IR camera's, with sigmas


def principal_point_shift(session):
    """Where a depth image's shift from the IR image went: the depth image's
    principal point, fitted from the session alone (cameras estimated) or
    against the IR camera given (cameras given; the depth_grid_offset row)."""
    truth = read_scenario(session)["cameras"]["ir"]["intrinsics"]
    depth = json.loads((newest_version(session) / "calibration.json").read_text())["cameras"]["depth"]
    sigma = depth["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"]
    return (f"depth cx {depth['cx'] - truth[2]:+.2f} +- {sigma[2]:.2f} px, "
            f"cy {depth['cy'] - truth[3]:+.2f} +- {sigma[3]:.2f} px from the true IR camera's")


def shift_in_principal_point(session, hidden):
    """True when the depth image's principal point moved from the depth camera
    session.json gives beyond 3 sigma, to within 3 sigma of the hidden shift
    (the depth image shifted by +dx moves its principal point by -dx), as
    run-pipeline's "depth image: its principal point is ..." line says."""
    shift = hidden.overlay.get("effects", {}).get("depth_grid_offset", {})
    given = json.loads((session / "session.json").read_text())["cameras"]["depth"]
    depth = json.loads((newest_version(session) / "calibration.json").read_text())["cameras"]["depth"]
    sigma = depth["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"]
    moved = [depth["cx"] - given["cx"], depth["cy"] - given["cy"]]
    hidden_moved = [-shift.get("dx_px", 0), -shift.get("dy_px", 0)]
    if not (sigma[2] > 0 and sigma[3] > 0):
        return False
    beyond = any(abs(m) > 3 * s for m, s in zip(moved, sigma[2:4]))
    agrees = all(abs(m - h) <= 3 * s for m, h, s in zip(moved, hidden_moved, sigma[2:4]))
    return beyond and agrees


def named_first(diagnosis):
    """The candidate the diagnosis ranks first when it recommends one or one
    helps at all; else the covariate it names."""
    if diagnosis.get("recommended"):
        return diagnosis["recommended"]
    if diagnosis.get("named_covariate"):
        return "covariate:" + diagnosis["named_covariate"]
    candidates = diagnosis.get("candidates") or []
    return candidates[0]["name"] if candidates else ""


def refit_command(build, session, recommended):
    if recommended.startswith("base_form:"):  # as the verdict's command says
        return [str(build / "refit"), str(session), "--base-form", recommended.split(":", 1)[1]]
    return [str(build / "refit"), str(session), "--add-effect", recommended]


def follow_verdict(args, session, row):
    """Again while the newest verdict recommends something not yet added, as
    issue 46 asks (at most --follow refits in all)."""
    while len(row.followed) < args.follow:
        nxt = json.loads((newest_version(session) / "report.json").read_text())["diagnosis"].get("recommended") or ""
        if not nxt or nxt in row.followed:
            return
        run(refit_command(args.build, session, nxt) + args.rule, "refit (again)")
        row.followed.append(nxt)


def bench(args, hidden, seed, out_dir):
    row = Row(hidden.name, seed)
    session = out_dir / f"{hidden.name}-seed{seed}"
    if session.exists():
        shutil.rmtree(session)
    scenario_file = out_dir / f"{hidden.name}.json"
    scenario_file.write_text(json.dumps(scenario_for(hidden, args.poses, args.frames, args.snapshots), indent=1))
    started = time.monotonic()
    try:
        run([str(args.build / "record-session"), "sim", "--scenario", str(scenario_file), "--seed", str(seed),
             "--out", str(session)], "record-session")
        if args.cameras == "given":
            give_true_cameras(session)
        run([str(args.build / "run-pipeline"), str(session)] + args.rule + args.pipeline_arg, "run-pipeline")
        diagnosis = json.loads((newest_version(session) / "report.json").read_text())["diagnosis"]
        row.ratio_before = row.ratio_after = diagnosis["ratio_to_floor"]
        if "depth_grid_offset" in hidden.overlay.get("effects", {}):
            row.principal_point_shift = principal_point_shift(session)
        row.named = named_first(diagnosis)
        if args.cameras == "given" and not diagnosis.get("recommended") and shift_in_principal_point(session, hidden):
            row.named = "depth_principal_point"
        row.first_right = row.named in hidden.right
        row.recommended = diagnosis.get("recommended") or ""
        row.complete = bool(diagnosis.get("complete"))
        candidates = diagnosis.get("candidates") or []
        ps = [c["p_value"] for c in candidates if c.get("p_value") is not None and c["reduction"] >= 0.03]
        row.min_p = min(ps) if ps else 1.0
        with open(out_dir / "rows.jsonl", "a") as log:
            log.write(json.dumps({"effect": hidden.name, "seed": seed, "ratio": diagnosis["ratio_to_floor"],
                                  "complete": row.complete, "recommended": row.recommended,
                                  "named_covariate": diagnosis.get("named_covariate"),
                                  "candidates": [{k: c.get(k) for k in ("name", "reduction", "p_value", "poses_better",
                                                                        "poses_compared", "p_value_beyond_cameras")}
                                                 for c in candidates],
                                  "covariates": [{k: c.get(k) for k in ("covariate", "level", "explained_share", "p_value")}
                                                 for c in diagnosis.get("covariates", [])[:6]],
                                  "verdict": diagnosis.get("verdict")}) + "\n")
        if args.check_first_only:
            pass  # judged on the first run alone: no refit to wait for
        elif row.recommended:
            run(refit_command(args.build, session, row.recommended) + args.rule, "refit")
            row.followed = [row.recommended]
            follow_verdict(args, session, row)
        elif diagnosis.get("named_covariate") and diagnosis.get("formula_hint") and not row.complete:
            # Outside the catalogue: the formula effect the verdict suggests, as a user would paste it.
            spec = session / "hunt_formula.json"
            spec.write_text(json.dumps({"schema_version": 2, "effects": [json.loads(diagnosis["formula_hint"])]}) + "\n")
            row.refit = "formula"
            run([str(args.build / "refit"), str(session), "--model", str(spec)] + args.rule, "refit (formula)")
        if (row.recommended or row.refit) and args.after_joint_run:
            # refit holds the joint cameras (and says so): the run it names
            # fits them with the refit's model instead.
            spec = session / "hunt_refit_model.json"
            spec.write_text(json.dumps(json.loads((newest_version(session) / "calibration.json").read_text())["model_spec"]))
            run([str(args.build / "run-pipeline"), str(session), "--model", str(spec)] + args.rule + args.pipeline_arg,
                "run-pipeline (the refit's model)")
        if row.recommended or row.refit:
            row.ratio_after = json.loads((newest_version(session) / "report.json").read_text())["diagnosis"]["ratio_to_floor"]
    except (RuntimeError, ValueError, KeyError, OSError) as e:
        row.error = str(e)[:200]
    row.seconds = time.monotonic() - started
    if not args.keep:
        shutil.rmtree(session, ignore_errors=True)
    return row


def summary_line(hidden, rows, first_only=False):
    n = len(rows)
    first = sum(r.first_right for r in rows)
    within = sum(r.ratio_after <= 1.15 for r in rows)
    recommends = sum(bool(r.recommended) for r in rows)
    failed = sum(bool(r.error) for r in rows)
    before = statistics.median(r.ratio_before for r in rows) if rows else float("nan")
    after = statistics.median(r.ratio_after for r in rows) if rows else float("nan")
    right = "nothing" if not hidden.right else " or ".join(hidden.right)
    first_cell = f"{recommends}/{n} recommend" if not hidden.right else f"{first}/{n}"
    within_cell = "not refitted (--check-first-only)" if first_only else f"{within}/{n}"
    ok = (recommends <= n // 10) if not hidden.right else (first >= 0.9 * n and (first_only or within >= 0.9 * n))
    return (f"| {hidden.name} | {right} | {first_cell} | {within_cell} | {recommends}/{n} | "
            f"{before:.2f} -> {after:.2f} | {failed} |"), ok and failed == 0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--effects", default=",".join(h.name for h in HIDDEN),
                        help="comma-separated rows: " + ", ".join(h.name for h in HIDDEN))
    parser.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1-10"))
    parser.add_argument("--poses", type=int, default=20)
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--snapshots", type=int, default=40)
    parser.add_argument("--out-dir", help="where sessions go (default: a temporary directory)")
    parser.add_argument("--keep", action="store_true", help="keep the sessions")
    parser.add_argument("--follow", type=int, default=3,
                        help="refits to follow in all while the verdict recommends (1: the first only)")
    parser.add_argument("--check", action="store_true", help="exit 1 when a row misses its target")
    parser.add_argument("--check-first-only", action="store_true",
                        help="judge only the ranked-first target, and make no refit (the pixel pattern's held-out "
                             "one is out of any model's reach: bench/results/hunt.md; CI's seeds that end near 1.15)")
    parser.add_argument("--cameras", choices=("estimated", "given"), default="estimated",
                        help="estimated: both cameras from the session, as a user runs it (default); "
                             "given: the true intrinsics written into session.json first")
    parser.add_argument("--build", default=str(ROOT / "build"), type=pathlib.Path)
    parser.add_argument("--judge-beyond-cameras", action="store_true",
                        help="run-pipeline and refit judge the model beyond the cameras (on trial: issue 46)")
    parser.add_argument("--after-joint-run", action="store_true",
                        help="after the refit, run run-pipeline --model with the refit's model and the --pipeline-arg "
                             "flags, as a refit of a --joint-cameras run says to (refit holds the joint cameras)")
    parser.add_argument("--pipeline-arg", action="append", default=[],
                        help="passed to run-pipeline as it is (repeatable), e.g. --pipeline-arg=--joint-cameras")
    args = parser.parse_args()
    args.rule = ["--judge-beyond-cameras"] if args.judge_beyond_cameras else []
    by_name = {h.name: h for h in HIDDEN}
    wanted = [name.strip() for name in args.effects.split(",") if name.strip()]
    for name in wanted:
        if name not in by_name:
            parser.error(f"--effects: unknown row {name!r} (known: {', '.join(by_name)})")
    out_dir = pathlib.Path(args.out_dir) if args.out_dir else pathlib.Path(tempfile.mkdtemp(prefix="hunt-"))
    out_dir.mkdir(parents=True, exist_ok=True)
    table, all_ok = [], True
    started, sessions = time.monotonic(), 0
    for name in wanted:
        rows = []
        for seed in args.seeds:
            row = bench(args, by_name[name], seed, out_dir)
            rows.append(row)
            sessions += 1
            print(f"{row.effect:20s} seed {row.seed:3d}  named {row.named or '-':28s} "
                  f"recommended {row.recommended or '-':22s} min p {row.min_p:.2g}  "
                  f"held-out/floor {row.ratio_before:.2f} -> {row.ratio_after:.2f}  {row.seconds:.0f} s"
                  + (f"  followed {' + '.join(row.followed)}" if len(row.followed) > 1 else "")
                  + (f"  {row.principal_point_shift}" if row.principal_point_shift else "")
                  + (f"  FAILED: {row.error}" if row.error else ""), flush=True)
        line, ok = summary_line(by_name[name], rows, args.check_first_only)
        table.append(line)
        all_ok = all_ok and ok
    print()
    print(f"cameras {args.cameras} ({'from the session, as a user runs it' if args.cameras == 'estimated' else 'the true intrinsics given'})"
          + ("; judged beyond the cameras" if args.rule else "")
          + ("; run-pipeline " + " ".join(args.pipeline_arg) if args.pipeline_arg else ""))
    print("| hidden | right answer | ranked first | held-out <= 1.15 floor after refit | recommends | "
          "median held-out/floor before -> after | failed runs |")
    print("|---|---|---|---|---|---|---|")
    print("\n".join(table))
    print(f"\n{sessions} sessions in {(time.monotonic() - started) / 60:.1f} min")
    if not args.out_dir and not args.keep:
        shutil.rmtree(out_dir, ignore_errors=True)
    return 1 if args.check and not all_ok else 0


if __name__ == "__main__":
    sys.exit(main())
