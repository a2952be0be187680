#!/usr/bin/python3
"""Calibration benchmark over randomized simulated sessions.

The tool was tuned on one simulated sensor; this records a fresh drawn
sensor, room and user-like session per seed (record-session sim --seed N),
calibrates it (run-pipeline) and compares the result with the truth stored in
the session itself (each recording's /truth scenario_json), one row per seed:

  paired      board frames paired / board frames (calibration.json metrics)
  err/sigma   the same error in units of the depth sigma the tool reported
              (report.json depth_uncertainty): do its own error bars hold?
  depth_err   max |model depth - true depth| / true depth at the image centre
              (x = y = 0) over the depth range, for the true raw value of each
              depth; through undistortion_grid.h5 first when the chosen model
              applies it
  sigma@1m    the depth sigma the tool reported at 1 m, relative to 1 m
  fx..cy      depth-camera intrinsics error (estimate - truth) / sigma
  source      cameras.depth_intrinsics_source
  model       the chosen model's name (its effects are not applied in depth_err)
  grid        the undistortion grid: "used" or "declined", and its held-out
              flat-wall sigma reduction (report.json undistortion)
  rec_s/run_s seconds to record and to calibrate

The summary line adds the colour camera's fx fy cx cy k1 k2 errors in units
of their reported sigmas, pooled over the seeds (RMS near 1: honest sigmas).

Usage (numpy and h5py: run with /usr/bin/python3):
  bench/calibration_benchmark.py --scenario examples/scenarios/random_stock.json --seeds 1-10 --check

With --check, exits 1 when any row misses its acceptance (stock: >= 95 %
paired, depth within 0.3 %, intrinsics within 3 sigma; wide-angle: >= 90 %
paired, depth within 0.5 %; either: the undistortion grid declined where
the truth hides no billowing, used where it does). Without it, exits 0
whenever the runs happened.
"""
import argparse
import dataclasses
import json
import math
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

# The simulator's IR presets (simulator/optics_presets.cc), only for scenarios
# that draw nothing and override nothing: a drawn scenario stores its cameras.
PRESET_IR_INTRINSICS = {
    "stock": (588.92, 587.89, 315.10, 252.12),
    "wide_angle": (373.35, 372.83, 324.78, 237.21),
}


@dataclasses.dataclass
class Acceptance:
    min_paired_share: float
    max_depth_error: float   # relative
    max_intrinsics_sigma: float  # |estimate - truth| / sigma; inf: not checked
    depth_range_m: tuple


ACCEPTANCE = {
    "stock": Acceptance(0.95, 0.003, 3.0, (0.6, 3.0)),
    "wide_angle": Acceptance(0.90, 0.005, math.inf, (0.4, 2.5)),
}


# --- the truth -------------------------------------------------------------

def true_raw(depth_model, z_m):
    """Inverse of the simulator's depth formation (sim::DepthFormation::RawFromDepth);
    for a millimetre scenario, the value the driver reports for depth z (unrounded)."""
    if depth_model.get("units") == "millimetre":
        return 1000 * (z_m - depth_model["mm_offset_m"]) / depth_model["mm_gain"]
    form = depth_model["form"]
    if form == "reciprocal":
        return (1.0 / z_m - depth_model["b"]) / depth_model["a"]
    if form == "tangent":
        return depth_model["k"] * (np.arctan(z_m / depth_model["c"]) - depth_model["b"])
    if form == "disparity":
        return depth_model["doff"] - 8 * depth_model["baseline_m"] * depth_model["focal_px"] / z_m
    raise ValueError(f"scenario depth_model.form: unknown form {form!r}")


def read_scenario(session):
    """The scenario the session was drawn from, as stored in its recordings."""
    for name in ("depthboard.h5", "planar.h5", "ir_chessboard.h5"):
        path = session / name
        if path.exists():
            with h5py.File(path, "r") as f:
                if "truth" in f and "scenario_json" in f["truth"].attrs:
                    text = f["truth"].attrs["scenario_json"]
                    return json.loads(text.decode() if isinstance(text, bytes) else text)
    raise ValueError(f"{session}: no recording holds /truth scenario_json")


def true_ir_intrinsics(scenario):
    ir = scenario.get("cameras", {}).get("ir", {})
    if "intrinsics" in ir:
        return tuple(ir["intrinsics"])
    return PRESET_IR_INTRINSICS[scenario["optics"]]


def known_cameras(scenario, which=("colour", "depth")):
    """The drawn true intrinsics, as session.json's `cameras` (schema_version 2)."""
    cams = scenario["cameras"]
    out = {}
    for key, name in (("colour", "colour"), ("ir", "depth")):
        if name not in which:
            continue
        fx, fy, cx, cy = cams[key]["intrinsics"]
        out[name] = {"image_size": [640, 480], "fx": fx, "fy": fy, "cx": cx, "cy": cy,
                     "distortion": list(cams[key].get("distortion", [0, 0, 0, 0, 0]))}
    return out


def give_true_cameras(session, which=("colour", "depth")):
    """Writes the drawn cameras into session.json, as a user with cameras
    calibrated elsewhere would (record-session --describe)."""
    path = session / "session.json"
    manifest = json.loads(path.read_text())
    manifest["schema_version"] = max(2, int(manifest.get("schema_version", 1)))
    manifest["cameras"] = known_cameras(read_scenario(session), which)
    path.write_text(json.dumps(manifest, indent=2) + "\n")


# --- the calibration -------------------------------------------------------

def newest_version(session):
    versions = sorted((session / "calibrations").glob("v[0-9][0-9][0-9][0-9]"))
    if not versions:
        raise ValueError(f"{session}/calibrations: no vNNNN version written")
    return versions[-1]


class UndistortionGrid:
    """undistortion_grid.h5, applied as model/undistortion_grid.cc does."""

    def __init__(self, path):
        with h5py.File(path, "r") as f:
            self.raw_nodes = np.asarray(f["raw_nodes"], dtype=float)
            self.extent = np.asarray(f["extent_x_min_x_max_y_min_y_max"], dtype=float)
            self.correction = np.asarray(f["correction"], dtype=float)

    def apply(self, raw, x, y):
        k_count, ny, nx = self.correction.shape
        if nx == 0 or k_count < 2:
            return raw
        x_min, x_max, y_min, y_max = self.extent
        fi = min(max((x - x_min) / (x_max - x_min) * nx - 0.5, 0.0), nx - 1.0)
        fj = min(max((y - y_min) / (y_max - y_min) * ny - 0.5, 0.0), ny - 1.0)
        k1 = int(np.searchsorted(self.raw_nodes, raw, side="right"))
        k1 = min(max(k1, 1), k_count - 1)
        fk = (raw - self.raw_nodes[k1 - 1]) / (self.raw_nodes[k1] - self.raw_nodes[k1 - 1])
        fk = min(max(fk, 0.0), 1.0)
        i0, j0 = int(fi), int(fj)
        i1, j1 = min(i0 + 1, nx - 1), min(j0 + 1, ny - 1)
        ti, tj = fi - i0, fj - j0
        value = 0.0
        for dk, wk in ((0, 1 - fk), (1, fk)):
            c = self.correction[k1 - 1 + dk]
            value += wk * ((1 - tj) * ((1 - ti) * c[j0, i0] + ti * c[j0, i1]) +
                           tj * ((1 - ti) * c[j1, i0] + ti * c[j1, i1]))
        return raw + value


def base_form_depth(model, raw):
    """Depth (m) of the chosen model's base form; effects are not applied."""
    p = {q["name"]: q["value"] for q in model["parameters"] if q["block"] == "base"}
    form = model["base_form"]
    if form == "reciprocal":
        return 1.0 / (p["a"] * raw + p["b"])
    if form == "tangent":
        return p["c"] * math.tan(raw / p["k"] + p["b"])
    if form == "disparity":
        return p["bf8"] / (p["doff"] - raw)
    if form == "linear_mm":
        return p["a"] * raw + p["b"]
    raise ValueError(f"calibration.json model.base_form: unknown form {form!r}")


def depth_error(calibration, version, scenario, depth_range_m, report=None, count=25):
    """Largest relative depth error at the image centre over the range, and
    the largest error in units of the depth uncertainty the tool itself
    reported there (report.json depth_uncertainty, interpolated in depth; nan
    without one): whether the tool's own error bars hold."""
    grid = None
    if calibration["model"].get("undistortion") and calibration.get("undistortion_grid"):
        grid = UndistortionGrid(version / calibration["undistortion_grid"])
    table = sorted((u["depth_m"], u["sigma_mm"]) for u in (report or {}).get("depth_uncertainty", []))
    worst, worst_sigmas = 0.0, (0.0 if table else math.nan)
    for z in np.linspace(depth_range_m[0], depth_range_m[1], count):
        raw = float(true_raw(scenario["depth_model"], z))
        if grid is not None:
            raw = grid.apply(raw, 0.0, 0.0)
        error = base_form_depth(calibration["model"], raw) - z
        worst = max(worst, abs(error) / z)
        if table:
            worst_sigmas = max(worst_sigmas, abs(error) / reported_sigma_m(table, z))
    return worst, worst_sigmas


def relative_sigma_at(report, depth_m):
    """The depth sigma report.json states at depth_m, relative to depth_m
    (interpolated in depth; nan without a table)."""
    table = sorted((u["depth_m"], u["sigma_mm"]) for u in (report or {}).get("depth_uncertainty", []))
    return reported_sigma_m(table, depth_m) / depth_m if table else math.nan


def reported_sigma_m(table, depth_m):
    """report.json's (depth_m, sigma_mm) table interpolated at depth_m, in metres."""
    return 1e-3 * float(np.interp(depth_m, [t[0] for t in table], [t[1] for t in table]))


def colour_errors(calibration, scenario):
    """(estimate - truth) / sigma of the colour camera's fx fy cx cy k1 k2,
    when the scenario drew the colour camera (randomized sensors); else [].
    Their pooled RMS near 1 says the colour sigmas, which every depth sigma
    builds on, are honest."""
    drawn = scenario.get("cameras", {}).get("colour", {})
    if "intrinsics" not in drawn:
        return []
    truth = list(drawn["intrinsics"]) + list(drawn["distortion"][:2])
    colour = calibration["cameras"]["colour"]
    estimates = [colour[n] for n in ("fx", "fy", "cx", "cy")] + colour["distortion_k1_k2_p1_p2_k3"][:2]
    sigmas = colour["stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"][:6]
    return [(e - t) / s for e, t, s in zip(estimates, truth, sigmas) if s > 0]


def intrinsics_errors(calibration, truth):
    """(estimate - truth) / sigma for fx fy cx cy; None where no sigma."""
    depth = calibration["cameras"]["depth"]
    sigmas = depth.get("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3") or []
    errors = []
    for i, name in enumerate(("fx", "fy", "cx", "cy")):
        sigma = sigmas[i] if i < len(sigmas) and sigmas[i] else 0
        errors.append((depth[name] - truth[i]) / sigma if sigma > 0 else None)
    estimates = [depth[n] for n in ("fx", "fy", "cx", "cy")]
    return errors, estimates


# --- one seed --------------------------------------------------------------

@dataclasses.dataclass
class Row:
    scenario: str
    seed: int
    failure: str = ""
    paired: int = 0
    board_frames: int = 0
    depth_error: float = math.nan
    depth_error_sigmas: float = math.nan  # in units of the tool's own reported depth sigma
    sigma_at_1m: float = math.nan  # the reported depth sigma at 1 m, relative (issue 46: median <= 0.3 %)
    intrinsics_sigma: list = dataclasses.field(default_factory=list)
    intrinsics_px: list = dataclasses.field(default_factory=list)
    source: str = ""
    colour_sigmas: list = dataclasses.field(default_factory=list)  # colour fx fy cx cy k1 k2 errors in sigmas
    record_s: float = 0.0
    run_s: float = 0.0
    model: str = ""
    grid_used: bool = False
    grid_expected: bool = False  # the truth hides billowing for the grid to undo
    wall_sigma_reduction: float = math.nan

    def paired_share(self):
        return self.paired / self.board_frames if self.board_frames else 0.0


def failure_message(output):
    """The line of a failed tool's output that says why: its "error:" line
    (with the most common rejection counted under it), a glog fatal line
    (a CHECK that aborted), or else the last line."""
    lines = [line.strip() for line in output.splitlines() if line.strip()] or ["no output"]
    for i, line in enumerate(lines):
        if line.startswith("error:"):
            counts = [l for l in lines[i + 1:] if re.match(r"\d+ x ", l)]
            commonest = max(counts, key=lambda l: int(l.split()[0]), default="")
            return line[len("error:"):].strip() + (f" ({commonest})" if commonest else "")
        if re.match(r"F\d{8} ", line):
            return "aborted: " + line.split("] ", 1)[-1]
    return lines[-1]


def run(command, what):
    """Runs a tool; raises with why it failed when it does."""
    started = time.monotonic()
    try:
        result = subprocess.run(command, capture_output=True, text=True)
    except OSError as e:  # the tool is not built
        raise RuntimeError(f"{what}: {e}") from e
    if result.returncode != 0:
        message = failure_message(result.stderr + "\n" + result.stdout)
        status = f"exit {result.returncode}" if result.returncode >= 0 else f"killed by signal {-result.returncode}"
        raise RuntimeError(f"{what} {status}: {message[:220]}")
    return time.monotonic() - started


def evaluate(session, row, acceptance):
    scenario = read_scenario(session)
    version = newest_version(session)
    calibration = json.loads((version / "calibration.json").read_text())
    report = json.loads((version / "report.json").read_text())
    metrics = calibration["metrics"]
    row.board_frames = int(metrics["board_frames"])
    row.paired = int(metrics["paired_frames"])
    if report.get("chosen_model") and report["chosen_model"] != calibration["model"]["name"]:
        raise ValueError(f"{version}: report.json chose {report['chosen_model']}, "
                         f"calibration.json {calibration['model']['name']}")
    row.model = calibration["model"]["name"]
    row.grid_used = calibration["model"].get("undistortion") is True
    row.grid_expected = "radial_billow" in scenario.get("effects", {})
    row.wall_sigma_reduction = report.get("undistortion", {}).get("wall_sigma_reduction_held_out", math.nan)
    row.depth_error, row.depth_error_sigmas = depth_error(calibration, version, scenario, acceptance.depth_range_m, report)
    row.sigma_at_1m = relative_sigma_at(report, 1.0)
    truth = true_ir_intrinsics(scenario)
    row.intrinsics_sigma, estimates = intrinsics_errors(calibration, truth)
    row.intrinsics_px = [e - t for e, t in zip(estimates, truth)]
    row.source = calibration["cameras"].get("depth_intrinsics_source", "?")
    row.colour_sigmas = colour_errors(calibration, scenario)


def bench_seed(args, scenario_file, seed, acceptance, out_dir):
    row = Row(pathlib.Path(scenario_file).stem, seed)
    session = out_dir / f"{row.scenario}-seed{seed}"
    if session.exists():
        shutil.rmtree(session)
    build = pathlib.Path(args.build)
    try:
        row.record_s = run([str(build / "record-session"), "sim", "--scenario", str(scenario_file),
                            "--seed", str(seed), "--out", str(session)], "record-session")
        if args.give_colour:
            give_true_cameras(session, which=("colour",))
        row.run_s = run([str(build / "run-pipeline"), str(session)] + args.pipeline_arg, "run-pipeline")
        evaluate(session, row, acceptance)
    except (RuntimeError, ValueError, KeyError, OSError) as e:
        row.failure = str(e) if not isinstance(e, KeyError) else f"missing key {e}"
    finally:
        if not args.keep and session.exists():
            shutil.rmtree(session)
    return row


# --- the table -------------------------------------------------------------

def failures(row, acceptance):
    """The acceptances a row misses, in words."""
    if row.failure:
        return ["failed"]
    missed = []
    if row.paired_share() < acceptance.min_paired_share:
        missed.append(f"paired {row.paired_share():.1%} < {acceptance.min_paired_share:.0%}")
    if not row.depth_error <= acceptance.max_depth_error:
        missed.append(f"depth {row.depth_error:.2%} > {acceptance.max_depth_error:.1%}")
    if math.isfinite(acceptance.max_intrinsics_sigma):
        if any(e is None for e in row.intrinsics_sigma):
            missed.append("intrinsics: no sigma")
        elif any(abs(e) > acceptance.max_intrinsics_sigma for e in row.intrinsics_sigma):
            missed.append(f"intrinsics > {acceptance.max_intrinsics_sigma:g} sigma")
    if row.grid_used != row.grid_expected:
        missed.append("grid used on a sensor without billowing" if row.grid_used else "grid declined on a billowing sensor")
    return missed


HEADER = (f"{'scenario':<18} {'seed':>4} {'paired':>9} {'depth_err':>9} {'err/sigma':>9} {'sigma@1m':>8} {'fx':>16} {'fy':>16} "
          f"{'cx':>16} {'cy':>16} {'source':<18} {'model':<26} {'grid':<15} {'rec_s':>6} {'run_s':>6}  verdict")


def intrinsic_cell(sigma_units, px):
    if sigma_units is None:
        return f"{px:+.1f}px no sigma"
    return f"{sigma_units:+.1f}s ({px:+.1f}px)"


def grid_cell(row):
    walls = "no walls" if math.isnan(row.wall_sigma_reduction) else f"{row.wall_sigma_reduction:+.0%}"
    return f"{'used' if row.grid_used else 'declined'} {walls}"


def format_row(row, acceptance):
    if row.failure:
        return f"{row.scenario:<18} {row.seed:>4} failed: {row.failure}"
    cells = [intrinsic_cell(s, p) for s, p in zip(row.intrinsics_sigma, row.intrinsics_px)]
    missed = failures(row, acceptance)
    verdict = "ok" if not missed else "; ".join(missed)
    return (f"{row.scenario:<18} {row.seed:>4} {row.paired:>4}/{row.board_frames:<4} {row.depth_error:>9.3%} "
            + f"{row.depth_error_sigmas:>9.1f} {row.sigma_at_1m:>8.3%} "
            + " ".join(f"{c:>16}" for c in cells)
            + f" {row.source:<18} {row.model:<26} {grid_cell(row):<15} {row.record_s:>6.1f} {row.run_s:>6.1f}  {verdict}")


def summary(rows, acceptances):
    ok = [r for r in rows if not r.failure]
    passed = sum(1 for r in rows if not failures(r, acceptances[r.scenario]))
    if not ok:
        return f"summary: {len(rows)} runs, all failed"
    depth = np.array([r.depth_error for r in ok])
    share = np.array([r.paired_share() for r in ok])
    return (f"summary: {len(rows)} runs, {len(rows) - len(ok)} failed, {passed} pass acceptance; "
            f"paired share median {np.median(share):.1%} min {share.min():.1%}; "
            f"depth error median {np.median(depth):.3%} max {depth.max():.3%}; "
            f"depth sigma at 1 m median {np.nanmedian([r.sigma_at_1m for r in ok]):.3%}; "
            f"record {np.mean([r.record_s for r in ok]):.1f} s, run {np.mean([r.run_s for r in ok]):.1f} s mean"
            + colour_summary(ok))


def colour_summary(rows):
    z = np.array([e for r in rows for e in r.colour_sigmas])
    if not z.size:
        return ""
    return f"; colour intrinsics' errors in their sigmas: RMS {np.sqrt(np.mean(z * z)):.2f} over {z.size}"


def parse_seeds(text):
    """'1-10' or '3' or '1,4,7'."""
    seeds = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        seeds.extend(range(int(lo), int(hi or lo) + 1))
    if not seeds:
        raise argparse.ArgumentTypeError(f"--seeds: expected e.g. 1-10, found {text!r}")
    return seeds


def acceptance_for(scenario_file, depth_range):
    optics = json.loads(pathlib.Path(scenario_file).read_text()).get("optics", "stock")
    base = ACCEPTANCE.get(optics, ACCEPTANCE["stock"])
    return dataclasses.replace(base, depth_range_m=tuple(depth_range)) if depth_range else base


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenario", action="append", required=True, help="scenario JSON (repeatable)")
    parser.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1-10"), help="e.g. 1-10 or 1,4,7")
    parser.add_argument("--out-dir", help="where sessions go (default: a temporary directory)")
    parser.add_argument("--keep", action="store_true", help="keep the sessions")
    parser.add_argument("--check", action="store_true", help="exit 1 when any row misses its acceptance")
    parser.add_argument("--build", default="build", help="build directory holding record-session, run-pipeline")
    parser.add_argument("--depth-range", type=float, nargs=2, metavar=("MIN_M", "MAX_M"),
                        help="depth range of the depth error (default: 0.6 3.0 stock, 0.4 2.5 wide-angle)")
    parser.add_argument("--pipeline-arg", action="append", default=[],
                        help="an argument passed on to run-pipeline (repeatable), e.g. --joint-cameras")
    parser.add_argument("--give-colour", action="store_true",
                        help="write the drawn colour camera into session.json before calibrating (what the "
                             "depth error is when the colour camera is known, e.g. calibrated elsewhere)")
    args = parser.parse_args()

    out_dir = pathlib.Path(args.out_dir or tempfile.mkdtemp(prefix="speckle-bench-"))
    out_dir.mkdir(parents=True, exist_ok=True)
    rows, acceptances = [], {}
    print(HEADER, flush=True)
    for scenario_file in args.scenario:
        acceptance = acceptance_for(scenario_file, args.depth_range)
        acceptances[pathlib.Path(scenario_file).stem] = acceptance
        for seed in args.seeds:
            print(f"[bench] {scenario_file} seed {seed}: recording and calibrating", file=sys.stderr, flush=True)
            row = bench_seed(args, scenario_file, seed, acceptance, out_dir)
            rows.append(row)
            print(format_row(row, acceptance), flush=True)
    print(summary(rows, acceptances), flush=True)
    if not args.out_dir and not args.keep:
        shutil.rmtree(out_dir, ignore_errors=True)
    if args.check and any(failures(r, acceptances[r.scenario]) for r in rows):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
