#!/usr/bin/python3
"""Every file apply-calibration writes, read back by a reader that is not ours:
PCL (pcl_convert_pcd_ascii_binary), Open3D, numpy, Pillow, ROS's
camera_calibration_parsers, OpenCV's FileStorage and PyYAML.

usage: apply_readback_test.py BUILD_DIR SOURCE_DIR SHARED_DATA
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

import cv2
import numpy as np
import open3d as o3d
import yaml
from PIL import Image
import camera_calibration_parsers

BUILD, SOURCE, SHARED = sys.argv[1:4]
failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print("FAIL:", message)


def run(*args):
    """The tool's output and log (stdout, then stderr); exits on failure."""
    result = subprocess.run(args, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"{' '.join(args)} exited {result.returncode}:\n{result.stderr}")
    return result.stdout + result.stderr


def same(a, b):
    """Equal arrays, NaN equal to NaN."""
    return a.shape == b.shape and bool(np.all((a == b) | (np.isnan(a) & np.isnan(b))))


def read_with_pcl(path, scratch):
    """PCL reads `path` and writes it again as binary PCD (exact, unlike its
    ASCII, which rounds); returns PCL's header, points and packed colours."""
    converted = os.path.join(scratch, "pcl.pcd")
    run("pcl_convert_pcd_ascii_binary", path, converted, "1")
    with open(converted, "rb") as f:
        data = f.read()
    end = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    header = dict(l.split(" ", 1) for l in data[:end].decode().splitlines() if not l.startswith("#"))
    records = np.frombuffer(data[end:], dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("rgb", "<u4")],
                            count=int(header["POINTS"]))  # PCL pads the file to a page
    return header, np.stack([records["x"], records["y"], records["z"]], axis=1), records["rgb"]


def colour_from_depth_in_launch(out):
    """The transform depth_to_rgb_tf.launch hands static_transform_publisher: (R, t, parent, child)."""
    node = ET.parse(os.path.join(out, "depth_to_rgb_tf.launch")).getroot().find("node")
    check(node.get("pkg") == "tf2_ros" and node.get("type") == "static_transform_publisher", "launch: the tf2 node")
    args = node.get("args").split()
    x, y, z, qx, qy, qz, qw = map(float, args[:7])
    R = np.array([[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
                  [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
                  [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
    return R, np.array([x, y, z]), args[7], args[8]


def check_registered(stem, points, out):
    """REP 118 registered depth: the TIFF (32FC1 m, NaN) and PNG (16UC1 mm, 0) against a z-buffer made here:
    each point moved by the launch file's transform and projected with rgb_camera_info.yaml through OpenCV."""
    R, t, parent, child = colour_from_depth_in_launch(out)
    check((parent, child) == ("camera_rgb_optical_frame", "camera_depth_optical_frame"), f"launch frames {parent} {child}")
    _, info = camera_calibration_parsers.readCalibration(os.path.join(out, "rgb_camera_info.yaml"))
    in_colour = points @ R.T + t
    pixels, _ = cv2.projectPoints(in_colour, np.zeros(3), np.zeros(3), np.array(info.K).reshape(3, 3), np.array(info.D))
    uv = np.rint(pixels.reshape(-1, 2)).astype(int)
    inside = (uv[:, 0] >= 0) & (uv[:, 0] < info.width) & (uv[:, 1] >= 0) & (uv[:, 1] < info.height) & (in_colour[:, 2] > 0)
    expected = np.full(info.width * info.height, np.inf)
    np.minimum.at(expected, uv[inside, 1] * info.width + uv[inside, 0], in_colour[inside, 2])
    expected[np.isinf(expected)] = np.nan
    tiff = cv2.imread(stem + ".registered.tiff", cv2.IMREAD_UNCHANGED)
    check(tiff is not None and tiff.dtype == np.float32 and tiff.shape == (info.height, info.width),
          f"registered TIFF: 32-bit float, {info.width} x {info.height}")
    ours = tiff.reshape(-1).astype(np.float64)
    both = ~np.isnan(ours) & ~np.isnan(expected)
    differ = np.mean(np.isnan(ours) != np.isnan(expected))
    close = np.mean(np.abs(ours[both] - expected[both]) < 1e-4)
    check(both.mean() > 0.3 and differ < 0.005 and close > 0.995,
          f"registered depth: {100 * both.mean():.1f} % of colour pixels hold one; {100 * differ:.2f} % differ in "
          f"having one and {100 * (1 - close):.2f} % in value from the z-buffer made with the ROS files")
    png = cv2.imread(stem + ".registered.png", cv2.IMREAD_UNCHANGED).reshape(-1).astype(np.int64)
    mm = np.where(np.isnan(ours), 0, np.rint(np.nan_to_num(ours) * 1000)).astype(np.int64)
    check(np.abs(png - mm).max() <= 1, "registered PNG: the TIFF's depths in millimetres, 0 where it holds NaN")


scratch = tempfile.mkdtemp(prefix="speckle-apply-readback-")
try:
    session = os.path.join(scratch, "s")
    shutil.copytree(os.path.join(SOURCE, "tests", "golden", "session"), session)
    run(os.path.join(BUILD, "run-pipeline"), session)
    out = os.path.join(scratch, "out")
    log = run(os.path.join(BUILD, "apply-calibration"), session, "--out", out, "--recording", "depthboard",
              "--frames", "0:2", "--format", "pcd,pcd-ascii,ply,csv,png,registered-png,registered-tiff")
    check("with colour registration" in log, f"the session's frames were registered to colour: {log[-300:]}")
    version = os.path.join(session, "calibrations", "v0001")
    with open(os.path.join(version, "calibration.json")) as f:
        calibration = json.load(f)
    with open(os.path.join(out, "applied.json")) as f:
        applied = json.load(f)
    check(applied["schema"] == "speckle.applied_frames" and applied["schema_version"] == 3, "applied.json schema")
    check(len(applied["frames"]) == 2, f"2 frames applied, found {len(applied['frames'])}")
    depth_camera = calibration["cameras"]["depth"]
    width, height = depth_camera["image_size"]

    for frame in applied["frames"]:
        stem = os.path.join(out, "depthboard", f"{frame['index']:06d}")
        # The CSV (numpy): the points that exist, by pixel.
        csv = np.loadtxt(stem + ".csv", delimiter=",", skiprows=1, dtype=np.float64)
        with open(stem + ".csv") as f:
            check(f.readline().strip() == "u,v,x_m,y_m,z_m,r,g,b", "CSV header")
        u, v = csv[:, 0].astype(int), csv[:, 1].astype(int)
        organized = np.full((height * width, 3), np.nan, dtype=np.float32)
        organized[v * width + u] = csv[:, 2:5].astype(np.float32)
        check(len(csv) == frame["points"], f"CSV has {len(csv)} points, applied.json says {frame['points']}")
        check(len(csv) > 0.3 * width * height, f"frame {frame['index']}: only {len(csv)} points")

        # PCD binary and ASCII through PCL: both organized, identical to the CSV.
        for name in (".pcd", ".ascii.pcd"):
            header, xyz, packed = read_with_pcl(stem + name, scratch)
            check(header["WIDTH"] == str(width) and header["HEIGHT"] == str(height), f"{name}: PCL sees {header['WIDTH']} x {header['HEIGHT']}")
            check(header["FIELDS"] == "x y z rgb", f"{name}: PCL fields {header['FIELDS']}")
            check(same(xyz, organized), f"{name}: PCL's points differ from the CSV's")
            found = ~np.isnan(organized[:, 2])
            rgb = np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], axis=1)[found]
            check(np.array_equal(rgb, csv[:, 5:8].astype(np.uint32)), f"{name}: PCL's colours differ from the CSV's")

        # PCD and PLY through Open3D.
        cloud = o3d.io.read_point_cloud(stem + ".pcd", remove_nan_points=False, remove_infinite_points=False)
        points = np.asarray(cloud.points).astype(np.float32)
        check(same(points, organized), "Open3D's PCD points differ from the CSV's")
        mesh = o3d.io.read_point_cloud(stem + ".ply")
        check(np.array_equal(np.asarray(mesh.points).astype(np.float32), csv[:, 2:5].astype(np.float32)),
              "Open3D's PLY points differ from the CSV's")
        check(np.array_equal(np.round(np.asarray(mesh.colors) * 255).astype(int), csv[:, 5:8].astype(int)),
              "Open3D's PLY colours differ from the CSV's")

        # 16-bit PNG (Pillow): millimetres, 0 where there is no point.
        image = Image.open(stem + ".png")
        check(image.mode in ("I;16", "I") and image.size == (width, height), f"PNG mode {image.mode} size {image.size}")
        mm = np.array(image, dtype=np.int64).reshape(-1)
        z = organized[:, 2]
        expected = np.where(np.isnan(z), 0, np.round(np.nan_to_num(z) * 1000.0)).astype(np.int64)
        check(np.abs(mm - expected).max() <= 1, f"PNG differs from the CSV's depth by up to {np.abs(mm - expected).max()} mm")

        # The clouds are unresampled: each point projects through the exported
        # depth camera (ROS camera_info) back onto the pixel it came from.
        name, info = camera_calibration_parsers.readCalibration(os.path.join(out, "depth_camera_info.yaml"))
        K = np.array(info.K).reshape(3, 3)
        D = np.array(info.D)
        pick = np.random.default_rng(0).choice(len(csv), 3000, replace=False)
        projected, _ = cv2.projectPoints(csv[pick, 2:5], np.zeros(3), np.zeros(3), K, D)
        error = np.abs(projected.reshape(-1, 2) - csv[pick, 0:2]).max()
        check(error < 0.02, f"points project {error:.4f} px from their pixels through depth_camera_info.yaml")

        # Depth registered to the colour camera, made again here from the CSV's points with the ROS files alone.
        check_registered(stem, csv[:, 2:5], out)

    # The launch file's transform is the inverse of the calibration's depth_from_colour.
    extrinsics = calibration["cameras"]["depth_from_colour"]
    R, t, _, _ = colour_from_depth_in_launch(out)
    depth_R, _ = cv2.Rodrigues(np.array(extrinsics["rotation_axis_angle_rad"]))
    check(np.allclose(R, depth_R.T, atol=1e-9) and np.allclose(t, -depth_R.T @ np.array(extrinsics["translation_m"]), atol=1e-8),
          "depth_to_rgb_tf.launch holds the colour-from-depth transform")
    with open(os.path.join(out, "README.txt")) as f:
        readme = f.read()
    check(all(words in readme for words in ("millimetres", "camera_depth_optical_frame", "registered.tiff", "reciprocal")),
          "README.txt states units, frames, the files and the model")
    # ROS camera_info (ROS's own parser) and OpenCV YAML (cv2 and PyYAML) hold the calibration's cameras.
    for file, key, camera_name in (("depth_camera_info.yaml", "depth", "depth"), ("rgb_camera_info.yaml", "colour", "rgb")):
        name, info = camera_calibration_parsers.readCalibration(os.path.join(out, file))
        camera = calibration["cameras"][key]
        check(name == camera_name, f"{file}: camera_name {name}")
        check((info.width, info.height) == tuple(camera["image_size"]), f"{file}: size {info.width} x {info.height}")
        check(list(info.K) == [camera["fx"], 0, camera["cx"], 0, camera["fy"], camera["cy"], 0, 0, 1], f"{file}: K {info.K}")
        check(list(info.D) == camera["distortion_k1_k2_p1_p2_k3"] and info.distortion_model == "plumb_bob", f"{file}: D {info.D}")
        check(list(info.P) == [camera["fx"], 0, camera["cx"], 0, 0, camera["fy"], camera["cy"], 0, 0, 0, 1, 0], f"{file}: P {info.P}")
    opencv_file = os.path.join(out, "cameras_opencv.yml")
    storage = cv2.FileStorage(opencv_file, cv2.FILE_STORAGE_READ)
    with open(opencv_file) as f:
        text = f.read().split("\n", 1)[1]  # PyYAML does not take OpenCV's "%YAML:1.0"
    yaml.SafeLoader.add_constructor("tag:yaml.org,2002:opencv-matrix", lambda loader, node: loader.construct_mapping(node, deep=True))
    plain = yaml.safe_load(text)
    check(storage.getNode("schema").string() == "speckle.cameras_opencv" and plain["schema_version"] == 1, "cameras_opencv.yml schema")
    for key in ("depth", "colour"):
        camera = calibration["cameras"][key]
        K = storage.getNode(f"{key}_camera_matrix").mat()
        check(np.array_equal(K, [[camera["fx"], 0, camera["cx"]], [0, camera["fy"], camera["cy"]], [0, 0, 1]]), f"cv2 {key} K")
        check(np.allclose(plain[f"{key}_camera_matrix"]["data"], K.reshape(-1), rtol=1e-15, atol=0), f"PyYAML {key} K")
        D = storage.getNode(f"{key}_distortion_coefficients").mat().reshape(-1)
        check(np.allclose(D, camera["distortion_k1_k2_p1_p2_k3"], rtol=1e-15, atol=0), f"cv2 {key} D")
    extrinsics = calibration["cameras"]["depth_from_colour"]
    R, _ = cv2.Rodrigues(np.array(extrinsics["rotation_axis_angle_rad"]))
    check(np.allclose(storage.getNode("depth_from_colour_rotation").mat(), R, atol=1e-12), "cv2 rotation")
    check(np.allclose(storage.getNode("depth_from_colour_translation_m").mat().reshape(-1), extrinsics["translation_m"], atol=1e-15), "cv2 translation")

    # A real libfreenect dump (depth only) with the same calibration.
    dump_out = os.path.join(scratch, "dump")
    log = run(os.path.join(BUILD, "apply-calibration"), "fakenect:" + os.path.join(SHARED, "fakenect_openiss_test"),
              "--calibration", version, "--out", dump_out, "--format", "png")
    check("depth only, no colour" in log and "colour registration" not in log,
          f"fakenect: the log says the frames had no colour to register: {log[-300:]}")
    with open(os.path.join(dump_out, "applied.json")) as f:
        dump = json.load(f)
    check(len(dump["frames"]) == 20, f"fakenect: {len(dump['frames'])} frames applied, expected 20")
    for frame in dump["frames"]:
        mm = np.array(Image.open(os.path.join(dump_out, frame["files"][0])), dtype=np.int64)
        check(np.count_nonzero(mm) == frame["points"] and frame["points"] > 0.3 * mm.size,
              f"fakenect frame {frame['index']}: {np.count_nonzero(mm)} depths in the PNG, {frame['points']} points")
        check(not frame["colour"], "fakenect frames have no colour")
finally:
    shutil.rmtree(scratch, ignore_errors=True)

if failures:
    sys.exit(f"{len(failures)} checks failed")
print("every file read back")
