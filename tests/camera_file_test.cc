// Camera files other tools write (formats/camera_file.h), read as the
// session's known intrinsics: each format's camera, a Kalibr chain's camera
// by name, mrcal's Python literal with its base-85 optimization inputs, an
// OpenCV file's standard deviations, and every lens this tool cannot hold
// refused by name. The files written by the real tools (ROS's
// camera_calibration_parsers, cv2.FileStorage, mrcal) are read in
// tests/camera_files_test.py.
#include "formats/camera_file.h"

#include <gtest/gtest.h>

#include "formats/python_literal.h"
#include "schemas/errors.h"
#include "test_util.h"

namespace speckle::formats {
namespace {

using speckle::testing::ScratchDir;

std::string Write(const ScratchDir& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir / name) << text;
  return (dir / name).string();
}

// A ROS-like camera, 640x480, as each file below gives it.
void ExpectCamera(const KnownIntrinsics& k, double k3 = 0.892) {
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 480);
  EXPECT_DOUBLE_EQ(k.fx, 529.3);
  EXPECT_DOUBLE_EQ(k.fy, 528.6);
  EXPECT_DOUBLE_EQ(k.cx, 306.2);
  EXPECT_DOUBLE_EQ(k.cy, 258.3);
  EXPECT_DOUBLE_EQ(k.distortion[0], 0.235);
  EXPECT_DOUBLE_EQ(k.distortion[3], -0.0009);
  EXPECT_DOUBLE_EQ(k.distortion[4], k3);
}

// The message of the InputError `read` throws ("" when it throws none).
template <typename F>
std::string Refusal(F read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A ROS camera_info's size and camera matrix (principal point x at cx).
std::string RosYaml(double cx) {
  return "image_width: 640\nimage_height: 480\ncamera_matrix:\n  rows: 3\n  cols: 3\n  data: [529.3, 0, " +
         std::to_string(cx) + ", 0, 528.6, 258.3, 0, 0, 1]\n";
}

const char* kKalibr = R"(cam0:
  cam_overlaps: [1]
  camera_model: pinhole
  distortion_coeffs: [0.235, -0.726, 0.0015, -0.0009]
  distortion_model: radtan
  intrinsics: [529.3, 528.6, 306.2, 258.3]
  resolution: [640, 480]
  rostopic: /camera/rgb/image_color
cam1:
  T_cn_cnm1:
  - [0.9999, 0.001, -0.002, -0.025]
  - [-0.001, 0.9999, 0.001, 0.0]
  - [0.002, -0.001, 0.9999, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  camera_model: pinhole
  distortion_coeffs: [-0.06, 0.3, 0.004, 0.005]
  distortion_model: radtan
  intrinsics: [580.0, 581.0, 319.5, 239.5]
  resolution: [640, 480]
  rostopic: /camera/ir/image
)";

TEST(CameraFile, AKalibrChainsCameraIsPickedByNameAndTheChoiceIsAskedForWhenThereAreSeveral) {
  ScratchDir dir;
  const std::string file = Write(dir, "camchain.yaml", kKalibr);
  const CameraFile cam0 = ReadCameraFile(file + "#cam0");
  EXPECT_EQ(cam0.format, "Kalibr camchain");
  EXPECT_FALSE(cam0.has_stddev);
  ExpectCamera(cam0.intrinsics, 0);
  // cam1's block sequence sits at its key's indentation (PyYAML's way), which OpenCV's reader needs moved.
  const KnownIntrinsics cam1 = ReadCameraFile(file + "#cam1").intrinsics;
  EXPECT_DOUBLE_EQ(cam1.fy, 581.0);
  EXPECT_DOUBLE_EQ(cam1.distortion[3], 0.005);
  EXPECT_NE(Refusal([&] { ReadCameraFile(file); }).find("holds cam0, cam1; name one, e.g. "), std::string::npos);
  EXPECT_NE(Refusal([&] { ReadCameraFile(file + "#cam2"); }).find("holds cam0, cam1"), std::string::npos);
}

TEST(CameraFile, MrcalsLiteralIsReadWithItsCommentsAndBase85Inputs) {
  ScratchDir dir;
  // b85 text holds '#', braces and brackets, which are neither comments nor structure inside a string.
  const std::string file = Write(dir, "colour.cameramodel", R"({
    'lensmodel':  'LENSMODEL_OPENCV5',
    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....
    'intrinsics': [ 529.3, 528.6, 306.2, 258.3, 0.235, -0.726, 0.0015, -0.0009, 0.892,],
    'extrinsics': [ 0, 0, 0, 0, 0, 1e-05,],
    'imagersize': [ 640, 480,],
    'icam_intrinsics': 0,
    'optimization_inputs': b'c$#{]}(Bx7%Ds)',
}
)");
  const CameraFile read = ReadCameraFile(file);
  EXPECT_EQ(read.format, "mrcal");
  ExpectCamera(read.intrinsics);
  EXPECT_EQ(PythonLiteralToJson("{'a': (1, 2.5e3,), 'b': True, 'c': None, 'd': \"it's\"}", "x").dump(),
            R"({"a":[1,2500.0],"b":true,"c":null,"d":"it's"})");
}

TEST(CameraFile, AnOpenCvFilesStandardDeviationsAreTheCamerasSigmas) {
  ScratchDir dir;
  const std::string file = Write(dir, "opencv.yaml", R"(%YAML:1.0
---
image_size: [640, 480]
cameraMatrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 529.3, 0., 306.2, 0., 528.6, 258.3, 0., 0., 1. ]
distCoeffs: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 0.235, -0.726, 0.0015, -0.0009, 0.892 ]
std_deviations_intrinsics: !!opencv-matrix
   rows: 18
   cols: 1
   dt: d
   data: [ 1.5, 1.4, 0.8, 0.7, 0.004, 0.02, 0.0002, 0.0002, 0.05, 0., 0., 0., 0., 0., 0., 0., 0., 0. ]
)");
  const CameraFile read = ReadCameraFile(file);
  EXPECT_EQ(read.format, "OpenCV FileStorage");
  ExpectCamera(read.intrinsics);
  ASSERT_TRUE(read.has_stddev);
  EXPECT_DOUBLE_EQ(read.intrinsics.stddev[0], 1.5);
  EXPECT_DOUBLE_EQ(read.intrinsics.stddev[8], 0.05);
}

TEST(CameraFile, LensesThisToolCannotHoldAreRefusedByName) {
  ScratchDir dir;
  std::string fisheye = kKalibr;
  fisheye.replace(fisheye.find("radtan"), 6, "equidistant");
  EXPECT_NE(Refusal([&] {
              ReadCameraFile(Write(dir, "fisheye.yaml", fisheye) + "#cam0");
            }).find("distortion_model equidistant is not a Brown-Conrady lens"),
            std::string::npos);
  const std::string rational =
      Write(dir, "rational.yaml",
            RosYaml(306.2) +
                "distortion_model: rational_polynomial\ndistortion_coefficients:\n  rows: 1\n  cols: 8\n"
                "  data: [0.235, -0.726, 0.0015, -0.0009, 0.892, 0.1, 0, 0]\n");
  EXPECT_NE(Refusal([&] { ReadCameraFile(rational); }).find("8 terms, the 6th not zero"), std::string::npos);
  const std::string splined = Write(dir, "splined.cameramodel",
                                    "{'lensmodel': 'LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=30_Ny=20_fov_x_deg=100',"
                                    " 'intrinsics': [1, 2, 3, 4], 'imagersize': [640, 480]}");
  EXPECT_NE(Refusal([&] { ReadCameraFile(splined); }).find("lensmodel LENSMODEL_SPLINED"), std::string::npos);
}

TEST(CameraFile, WhatIsNotACameraIsRefusedNamingTheFile) {
  ScratchDir dir;
  const std::string json = Write(dir, "session.json", R"({"cameras": {"colour": {"fx": 500}}})");
  EXPECT_NE(Refusal([&] { ReadCameraFile(json); }).find(json + ": "), std::string::npos);
  const std::string no_size =
      Write(dir, "no_size.yaml", "camera_matrix: [529.3, 0, 306.2, 0, 528.6, 258.3, 0, 0, 1]\n");
  EXPECT_NE(Refusal([&] { ReadCameraFile(no_size); }).find("no image size"), std::string::npos);
  const std::string outside = Write(dir, "outside.yaml", RosYaml(906.2));
  EXPECT_NE(Refusal([&] { ReadCameraFile(outside); }).find("cx"), std::string::npos);
  EXPECT_NE(Refusal([&] { ReadCameraFile((dir / "missing.yaml").string()); }).find("cannot be read"),
            std::string::npos);
  // Issue 47's outside probe: "abc" was read as 1.8e308 (then refused as out
  // of range), and a folder as content that is not a map.
  std::string text = RosYaml(306.2);
  text.replace(text.find("529.3"), 5, "abc");
  const std::string word = Write(dir, "word.yaml", text);
  EXPECT_NE(Refusal([&] { ReadCameraFile(word); }).find(word + ": data[0]: expected a number, found \"abc\""),
            std::string::npos);
  std::filesystem::create_directories(dir / "cams");
  EXPECT_NE(Refusal([&] { ReadCameraFile((dir / "cams").string()); }).find("cams: a folder, not a camera file"),
            std::string::npos);
}

}  // namespace
}  // namespace speckle::formats
