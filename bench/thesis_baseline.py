#!/usr/bin/python3
"""The thesis's own toolchain, as a small Python/OpenCV baseline for bench/speed_benchmark.py.

What the thesis did (docs/domain.md, "The depthboard procedure", chapter 3),
with nothing of Speckle's: no diagnosis, no undistortion, no uncertainty.

1. Colour frames: find the chessboard's interior corners (findChessboardCorners,
   cornerSubPix) and calibrate the colour camera (calibrateCamera): each
   board pose, hence each interior corner's depth in metres.
2. IR frames of the chessboard (the ir_chessboard recording): calibrate the IR
   camera the same way (the thesis found the depth camera's 4-point pose weak
   and calibrated the IR camera separately). A session without them (most
   recordings) takes the stock Kinect's published IR camera (580 px, centred).
3. Depth frames: locate the board around where the colour corners are, keep
   the depths near its centre's, find the quadrilateral outline (contours and
   polygon approximation), its four vertices the board's exterior corners;
   solve the board's pose in the depth camera from them (solvePnP).
4. Project the interior corners into the depth image with that pose, read the
   raw values there and pair each with the corner's depth from the colour pose.
5. Fit the reciprocal form 1/z = a raw + b by least squares; print a, b and
   the residual in raw units.

Usage: bench/thesis_baseline.py SESSION_DIR     (numpy, h5py, cv2: /usr/bin/python3)
Prints one JSON line: pairs, frames paired, a, b, rms, seconds.
"""
import json
import pathlib
import sys
import time

import cv2
import h5py
import numpy as np

CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.01)
NO_READING = 2047


def board_points(squares, square_m):
    """Interior corners (row-major, as OpenCV finds them) and the four exterior corners."""
    cols, rows = squares[0] - 1, squares[1] - 1
    grid = np.zeros((rows * cols, 3), np.float32)
    grid[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * square_m
    outer = np.array([[-1, -1, 0], [cols, -1, 0], [cols, rows, 0], [-1, rows, 0]], np.float32) * square_m
    return (cols, rows), grid, outer


def detect(images, pattern):
    found = {}
    for i, image in enumerate(images):
        ok, corners = cv2.findChessboardCorners(image, pattern, cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
        if ok:
            found[i] = cv2.cornerSubPix(image, corners, (5, 5), (-1, -1), CRITERIA)
    return found


def calibrate(found, grid, size):
    keys = sorted(found)
    _, K, dist, rvecs, tvecs = cv2.calibrateCamera([grid] * len(keys), [found[k] for k in keys], size, None, None)
    return K, dist, dict(zip(keys, zip(rvecs, tvecs)))


def depth_quad(depth, corners):
    """The board's outline in the depth image near the colour corners: 4 vertices or None."""
    x0, y0 = corners.reshape(-1, 2).min(axis=0)
    x1, y1 = corners.reshape(-1, 2).max(axis=0)
    w, h = x1 - x0, y1 - y0
    x0, x1 = int(max(0, x0 - 0.4 * w)), int(min(depth.shape[1], x1 + 0.4 * w))
    y0, y1 = int(max(0, y0 - 0.4 * h)), int(min(depth.shape[0], y1 + 0.4 * h))
    window = depth[y0:y1, x0:x1]
    cy, cx = window.shape[0] // 2, window.shape[1] // 2
    centre = window[max(0, cy - 5):cy + 5, max(0, cx - 5):cx + 5]
    centre = centre[centre != NO_READING]
    if centre.size == 0:
        return None
    mask = ((np.abs(window.astype(np.int32) - int(np.median(centre))) < 15) & (window != NO_READING)).astype(np.uint8)
    count, labels = cv2.connectedComponents(mask)
    label = labels[cy, cx]
    if label == 0:
        return None
    contours, _ = cv2.findContours((labels == label).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    contour = max(contours, key=cv2.contourArea)
    quad = cv2.approxPolyDP(contour, 0.03 * cv2.arcLength(contour, True), True)
    if len(quad) != 4:
        return None
    return quad.reshape(4, 2).astype(np.float32) + np.float32([x0, y0])


def pair(depth, colour_corners, colour_K, colour_dist, colour_pose, ir_K, ir_dist, grid, outer):
    """(raw, depth_m) of every interior corner of one frame, or None."""
    quad = depth_quad(depth, colour_corners)
    if quad is None:
        return None
    # Match each quad vertex to the nearest exterior corner as the colour camera sees it.
    rvec, tvec = colour_pose
    outer_in_colour, _ = cv2.projectPoints(outer, rvec, tvec, colour_K, colour_dist)
    outer_in_colour = outer_in_colour.reshape(4, 2)
    order = [int(np.argmin(np.linalg.norm(quad - p, axis=1))) for p in outer_in_colour]
    if len(set(order)) != 4:
        return None
    ok, r_depth, t_depth = cv2.solvePnP(outer, quad[order], ir_K, ir_dist, flags=cv2.SOLVEPNP_IPPE)
    if not ok:
        return None
    projected, _ = cv2.projectPoints(grid, r_depth, t_depth, ir_K, ir_dist)
    uv = np.rint(projected.reshape(-1, 2)).astype(int)
    inside = (uv[:, 0] >= 0) & (uv[:, 0] < depth.shape[1]) & (uv[:, 1] >= 0) & (uv[:, 1] < depth.shape[0])
    R, _ = cv2.Rodrigues(rvec)
    z = (grid @ R.T + tvec.reshape(1, 3))[:, 2]  # each corner's depth from the colour pose
    raw = np.full(len(grid), NO_READING, np.float64)
    raw[inside] = depth[uv[inside, 1], uv[inside, 0]]
    keep = inside & (raw != NO_READING)
    return raw[keep], z[keep]


def main():
    start = time.perf_counter()
    session = pathlib.Path(sys.argv[1])
    manifest = json.loads((session / "session.json").read_text())
    pattern, grid, outer = board_points(manifest["rig"]["squares"], manifest["rig"]["square_size_m"])
    with h5py.File(session / "depthboard.h5", "r") as f:
        colour = f["colour/frames"][:]
        depth = f["depth/frames"][:]
    grey = [cv2.cvtColor(c, cv2.COLOR_RGB2GRAY) for c in colour]
    colour_found = detect(grey, pattern)
    colour_K, colour_dist, colour_poses = calibrate(colour_found, grid, grey[0].shape[::-1])
    ir_camera = "calibrated from ir_chessboard.h5"
    if (session / "ir_chessboard.h5").exists():
        with h5py.File(session / "ir_chessboard.h5", "r") as f:
            ir = f["ir/frames"][:]
        ir8 = [cv2.normalize(i, None, 0, 255, cv2.NORM_MINMAX).astype(np.uint8) for i in ir]
        ir_K, ir_dist, _ = calibrate(detect(ir8, pattern), grid, ir8[0].shape[::-1])
    else:  # most recordings: the stock Kinect's published IR camera, as a user without IR images would take it
        ir_camera = "nominal (no IR recording)"
        ir_K, ir_dist = np.array([[580.0, 0, 319.5], [0, 580.0, 239.5], [0, 0, 1]]), np.zeros(5)
    raws, depths, frames = [], [], 0
    for i, corners in colour_found.items():
        paired = pair(depth[i], corners, colour_K, colour_dist, colour_poses[i], ir_K, ir_dist, grid, outer)
        if paired is None or len(paired[0]) == 0:
            continue
        raws.append(paired[0])
        depths.append(paired[1])
        frames += 1
    raw, z = np.concatenate(raws), np.concatenate(depths)
    # The reciprocal form is linear in its parameters: 1/z = a raw + b.
    A = np.stack([raw, np.ones_like(raw)], axis=1)
    (a, b), *_ = np.linalg.lstsq(A, 1 / z, rcond=None)
    residual_raw = raw - (1 / z - b) / a
    print(json.dumps({"frames": len(colour), "frames_paired": frames, "pairs": int(len(raw)), "a": a, "b": b,
                      "rms_raw": float(np.sqrt(np.mean(residual_raw ** 2))), "ir_camera": ir_camera,
                      "seconds": time.perf_counter() - start}))


if __name__ == "__main__":
    main()
