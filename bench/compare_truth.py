#!/usr/bin/python3
"""The simulator's truth behind a compare_benchmark.py run: for each seed's
same-sensor pair (a-SEED, b-SEED in --work), each calibration's true depth
error at the image centre in its report's own sigmas, and the pair's
difference in sigma A + sigma B and in sqrt(sigma A^2 + sigma B^2), at
0.8, 1.5 and 3 m. Whether a "differ" comes from sigmas that are too small
or from a 1-sigma rule (bench/results/compare.md).

usage (numpy and h5py: /usr/bin/python3):
  bench/compare_truth.py WORK_DIR SEED [SEED ...]
"""
import json
import math
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import calibration_benchmark as cb  # noqa: E402


def error_and_sigma(session, z):
    version = cb.newest_version(session)
    calibration = json.loads((version / "calibration.json").read_text())
    report = json.loads((version / "report.json").read_text())
    raw = float(cb.true_raw(cb.read_scenario(session)["depth_model"], z))
    table = sorted((u["depth_m"], u["sigma_mm"]) for u in report["depth_uncertainty"])
    return cb.base_form_depth(calibration["model"], raw) - z, cb.reported_sigma_m(table, z)


def main():
    work = pathlib.Path(sys.argv[1])
    for seed in sys.argv[2:]:
        cells = []
        for z in (0.8, 1.5, 3.0):
            ea, sa = error_and_sigma(work / f"a-{seed}", z)
            eb, sb = error_and_sigma(work / f"b-{seed}", z)
            d = abs(eb - ea)
            cells.append(f"{z} m: A {ea / sa:+.1f}s B {eb / sb:+.1f}s, difference {d / (sa + sb):.2f} (sA+sB) "
                         f"{d / math.hypot(sa, sb):.2f} (quadrature)")
        print(seed, " | ".join(cells))


main()
