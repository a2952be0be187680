#!/usr/bin/python3
"""What a boards-only session allows a per-pixel pattern model, held out by pose.

For each kept session (bench/hunt_benchmark.py --keep), from the first
calibration's samples.h5 and its noise floor, with the residuals of a
reciprocal-like base (raw against 1, 1/z, 1/z^2):

  unseen   the share of samples no sample of any other pose comes within
           one pattern feature (--feature-px) of
  bound    the held-out RMS over the floor if every other sample were
           predicted to the floor exactly and the unseen ones not at all:
           no model fitted to the other poses can end below it
  local    the held-out RMS over the floor when each sample is predicted by
           the mean residual of the other poses' samples within --near-px
           (scaled by the true decay), a model-free estimate of what the
           other poses know

Usage: bench/pattern_coverage_bound.py SESSION [SESSION ...]
"""
import argparse
import json
import pathlib

import h5py
import numpy as np


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sessions", nargs="+", type=pathlib.Path)
    parser.add_argument("--feature-px", type=float, default=25)
    parser.add_argument("--near-px", type=float, default=8)
    parser.add_argument("--decay-per-raw", type=float, default=0.004, help="the hidden pattern's decay")
    args = parser.parse_args()
    for session in args.sessions:
        version = session / "calibrations" / "v0001"
        floor = json.loads((version / "report.json").read_text())["diagnosis"]["noise_floor"]["floor_raw"]
        with h5py.File(version / "samples.h5", "r") as f:
            u, v, raw, z, pose = (f[k][:] for k in ("u", "v", "raw", "depth_m", "pose"))
        base = np.c_[np.ones_like(z), 1 / z, 1 / z**2]
        r = raw - base @ np.linalg.lstsq(base, raw, rcond=None)[0]
        unseen = np.zeros(len(r), bool)
        local = np.zeros(len(r))
        for p in np.unique(pose):
            others = pose != p
            for i in np.where(pose == p)[0]:
                d2 = (u[others] - u[i]) ** 2 + (v[others] - v[i]) ** 2
                unseen[i] = not np.any(d2 <= args.feature_px**2)
                near = d2 <= args.near_px**2
                if near.any():
                    scale = np.exp(-args.decay_per_raw * (raw[i] - raw[others][near]))
                    local[i] = np.mean(r[others][near] * scale)
        bound = np.sqrt(np.mean(np.where(unseen, r * r, floor * floor))) / floor
        print(f"{session.name}: unseen {unseen.mean():.2f}, bound {bound:.2f}x the floor, "
              f"local {np.sqrt(np.mean((r - local) ** 2)) / floor:.2f}x (base {np.sqrt(np.mean(r * r)) / floor:.2f}x)")


if __name__ == "__main__":
    main()
