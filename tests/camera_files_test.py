#!/usr/bin/env python3
"""Camera files written by the real tools, given to record-session (issue 48).

A simulated sensor's true colour camera is written by
  - ROS's camera_calibration_parsers (its `convert` tool writes the YAML the
    calibrator's ost.yaml is, from the calibrator's .ini),
  - OpenCV's cv2.FileStorage, as YAML and as XML,
  - mrcal (python3-mrcal's cameramodel.write),
and each is given to record-session --colour-camera for the same simulated
session. Checks:
  - each gives the same colour camera in session.json, the true one to the
    digits the file holds;
  - with --colour-camera-sigma its sigmas are a prior there, and they reach
    the depth sigma: run-pipeline states a larger depth sigma than with
    --colour-camera-exact, says the focal length is known as session.json
    states it, and calls the one camera a prior and the other exact.

usage: camera_files_test.py BUILD_DIR SOURCE_DIR [WORK_DIR]
"""
import json
import pathlib
import subprocess
import sys
import tempfile

import cv2
import mrcal
import numpy as np

BUILD, SOURCE = pathlib.Path(sys.argv[1]).resolve(), pathlib.Path(sys.argv[2]).resolve()
WORK = pathlib.Path(sys.argv[3]) if len(sys.argv) > 3 else pathlib.Path(tempfile.mkdtemp(prefix="camera-files-"))
SCENARIO = SOURCE / "bench" / "speed_user_20poses.json"
SEED = "2"
CONVERT = "/usr/lib/camera_calibration_parsers/convert"
sys.path.insert(0, str(SOURCE / "bench"))
import calibration_benchmark as bench  # noqa: E402  (read_scenario)

failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what, flush=True)
    if not ok:
        failures.append(what)


def run(*args):
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(map(str, args))} failed ({done.returncode}):\n{done.stdout[-2000:]}{done.stderr[-3000:]}")
    return done.stdout + done.stderr


def record(name, *camera_flags, purpose=None):
    out = WORK / name
    run(BUILD / "record-session", "sim", "--scenario", SCENARIO, "--seed", SEED, "--out", out,
        *(["--purpose", purpose] if purpose else []), *camera_flags)
    return out


def colour_in(session):
    return json.loads((session / "session.json").read_text())["cameras"]["colour"]


def write_files(fx, fy, cx, cy, lens):
    """The camera as each tool writes it: {label: path}."""
    matrix = np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]])
    files = {}
    # camera_calibration_parsers: the calibrator's .ini (ROS's oST format) converted to its YAML.
    ini = WORK / "ost.ini"
    rows = "\n".join(" ".join(f"{v:.17g}" for v in row) for row in matrix)
    ini.write_text(f"# oST version 5.0 parameters\n\n[image]\n\nwidth\n640\n\nheight\n480\n\n[rgb]\n\n"
                   f"camera matrix\n{rows}\n\ndistortion\n{' '.join(f'{v:.17g}' for v in lens)}\n\n"
                   "rectification\n1 0 0\n0 1 0\n0 0 1\n\n"
                   f"projection\n{fx:.17g} 0 {cx:.17g} 0\n0 {fy:.17g} {cy:.17g} 0\n0 0 1 0\n")
    files["camera_calibration_parsers YAML"] = WORK / "ost.yaml"
    run(CONVERT, ini, files["camera_calibration_parsers YAML"])
    for ext in ("yaml", "xml"):
        path = WORK / f"opencv.{ext}"
        storage = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
        storage.write("image_width", 640)
        storage.write("image_height", 480)
        storage.write("camera_matrix", matrix)
        storage.write("distortion_coefficients", np.array([lens]))
        storage.release()
        files[f"cv2.FileStorage {ext.upper()}"] = path
    files["mrcal"] = WORK / "colour.cameramodel"
    mrcal.cameramodel(intrinsics=("LENSMODEL_OPENCV5", np.array([fx, fy, cx, cy, *lens])),
                      imagersize=np.array([640, 480])).write(str(files["mrcal"]))
    return files


def sigma_near(report, depth_m):
    rows = [r for r in report["depth_uncertainty"] if not r["extrapolated"]]
    return min(rows, key=lambda r: abs(r["depth_m"] - depth_m))["sigma_mm"]


def newest_report(session):
    return json.loads(sorted((session / "calibrations").glob("v*"))[-1].joinpath("report.json").read_text())


def sigma_reach(with_sigma, exact):
    """The prior's sigmas reach the depth sigma, in the joint calibration (the
    default: the camera refined within them, its joint covariance carried) and
    in the separate steps (the camera held as given, its sigmas carried)."""
    summary = run(BUILD / "run-pipeline", with_sigma)
    exact_summary = run(BUILD / "run-pipeline", exact)
    check("colour given in the session, with sigmas (fx ± " in summary and
          "colour given in the session, taken as exact" in exact_summary,
          "the summary's cameras line says which camera is a prior and which is exact")
    check("refined within its stated sigmas: fx" in summary, "the joint calibration refines the prior within it")
    # Refined from 20 poses' chessboards, the 1 % prior ends near 0.05 %: it still loosens the depth
    # (0.54 mm against 0.30 mm near 1 m on 2026-12-07), by less than in the separate steps below.
    wide, narrow = (sigma_near(newest_report(s), 1.0) for s in (with_sigma, exact))
    check(wide > 1.25 * narrow, f"jointly, a 1 % focal-length prior widens the depth sigma near 1 m: {wide:.2f} mm "
                                f"against {narrow:.2f} mm taken as exact")
    summary = run(BUILD / "run-pipeline", with_sigma, "--separate-cameras")
    run(BUILD / "run-pipeline", exact, "--separate-cameras")
    wide, narrow = (sigma_near(newest_report(s), 1.0) for s in (with_sigma, exact))
    check(wide > 2 * narrow, f"apart, a 1 % focal-length prior widens the depth sigma near 1 m: {wide:.2f} mm "
                             f"against {narrow:.2f} mm taken as exact")
    check("as session.json states it" in summary, "the summary says where the focal length's sigma came from")


def main():
    WORK.mkdir(parents=True, exist_ok=True)
    # The sensor the seed draws, and its true colour camera.
    truth_session = record("truth", purpose="planar")
    colour = bench.read_scenario(truth_session)["cameras"]["colour"]
    fx, fy, cx, cy = colour["intrinsics"]
    files = write_files(fx, fy, cx, cy, colour["distortion"])
    sigma = f"{0.01 * fx:.3f},{0.01 * fy:.3f},2,2"
    given = {}
    for label, path in files.items():
        session = record(label.replace(" ", "_").replace(".", "_"), "--colour-camera", path,
                         "--colour-camera-sigma", sigma, purpose="planar")
        given[label] = colour_in(session)
    reference = given["camera_calibration_parsers YAML"]
    truth = {"fx": fx, "fy": fy, "cx": cx, "cy": cy}
    check(all(abs(reference[k] - v) <= 1e-9 * abs(v) for k, v in truth.items())
          and np.allclose(reference["distortion"], colour["distortion"], rtol=1e-9, atol=1e-15),
          f"ROS's YAML gives the true colour camera ({reference['fx']:.6f} against {fx:.6f})")
    for label, camera in given.items():
        same = all(np.allclose(camera[k], reference[k], rtol=1e-8, atol=1e-12)
                   for k in ("fx", "fy", "cx", "cy", "distortion", "image_size", "stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3"))
        check(same, f"{label} gives the same colour camera and its sigmas as ROS's YAML")
    # The sigmas reach the depth sigma.
    with_sigma = record("with_sigma", "--colour-camera", files["camera_calibration_parsers YAML"],
                        "--colour-camera-sigma", sigma)
    exact = record("exact", "--colour-camera", files["camera_calibration_parsers YAML"], "--colour-camera-exact")
    check("stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3" not in colour_in(exact), "--colour-camera-exact writes no sigmas")
    sigma_reach(with_sigma, exact)
    if failures:
        sys.exit(f"{len(failures)} check(s) failed: " + "; ".join(failures))
    print("all camera-file checks passed")


main()
