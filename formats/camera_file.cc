#include "formats/camera_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <regex>
#include <sstream>

#include "formats/python_literal.h"
#include "schemas/errors.h"

namespace speckle::formats {
namespace {

namespace fs = std::filesystem;

std::string ReadText(const fs::path& path) {
  // A folder read as empty text was called malformed content; a FIFO or a
  // device would block or never end.
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw InputError(path.string() + ": a folder, not a camera file (ROS YAML, OpenCV YAML/XML, mrcal, Kalibr)");
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))
    throw InputError(path.string() + ": not a regular file (a camera file is read from disk)");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path.string() + ": cannot be read (a camera file: ROS YAML, OpenCV YAML/XML, mrcal, Kalibr)");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A lens of up to 5 Brown-Conrady terms, or more whose extra terms are all
// zero; anything else is a lens model this tool does not hold.
std::array<double, 5> BrownConrady(const std::vector<double>& terms, const std::string& where) {
  std::array<double, 5> lens{};
  if (terms.size() != 0 && terms.size() != 4 && terms.size() < 5)
    throw InputError(fmt::format("{}: {} terms; expected k1 k2 p1 p2 [k3]", where, terms.size()));
  for (std::size_t i = 5; i < terms.size(); ++i)
    if (terms[i] != 0)
      throw InputError(
          fmt::format("{}: {} terms, the {}th not zero (a rational or thin-prism lens); Speckle's "
                      "cameras are k1 k2 p1 p2 k3, and dropping the others would change the camera",
                      where, terms.size(), i + 1));
  std::copy_n(terms.begin(), std::min<std::size_t>(terms.size(), 5), lens.begin());
  return lens;
}

// A node's numbers: a sequence, an OpenCV matrix, or a ROS {rows, cols, data}
// map. `where` (the file) names an element that is not a number: OpenCV reads
// "abc" as the largest double.
std::vector<double> Numbers(const cv::FileNode& node, const std::string& where) {
  if (node.isMap() && !node["data"].empty() && node["dt"].empty()) return Numbers(node["data"], where);
  if (node.isMap()) {
    cv::Mat m;
    node >> m;
    m.convertTo(m, CV_64F);
    return std::vector<double>(m.begin<double>(), m.end<double>());
  }
  std::vector<double> out;
  for (const auto& item : node) {
    if (!item.isReal() && !item.isInt())
      throw InputError(fmt::format("{}: {}[{}]: expected a number, found {}", where, node.name(), out.size(),
                                   item.isString() ? "\"" + std::string(item) + "\"" : std::string("no number")));
    out.push_back(item.real());
  }
  if (node.isReal() || node.isInt()) out.push_back(node.real());
  return out;
}

cv::FileNode FirstOf(const cv::FileNode& root, std::initializer_list<const char*> names) {
  for (const char* name : names)
    if (!root[name].empty()) return root[name];
  return {};
}

KnownIntrinsics FromMatrix(const std::vector<double>& k, int width, int height, const std::string& where) {
  if (k.size() != 9)
    throw InputError(fmt::format("{}: the camera matrix has {} numbers, expected 3x3", where, k.size()));
  KnownIntrinsics out;
  out.width = width, out.height = height;
  out.fx = k[0], out.fy = k[4], out.cx = k[2], out.cy = k[5];
  return out;
}

CameraFile FromRos(const cv::FileNode& root, const std::string& file) {
  const std::string model = root["distortion_model"].empty() ? "plumb_bob" : std::string(root["distortion_model"]);
  if (model != "plumb_bob" && model != "rational_polynomial")
    throw InputError(file + ": distortion_model " + model + " is not a Brown-Conrady lens (plumb_bob)");
  CameraFile out{FromMatrix(Numbers(root["camera_matrix"], file), static_cast<int>(root["image_width"].real()),
                            static_cast<int>(root["image_height"].real()), file + ": camera_matrix"),
                 "ROS camera_info"};
  out.intrinsics.distortion =
      BrownConrady(Numbers(root["distortion_coefficients"], file), file + ": distortion_coefficients");
  return out;
}

CameraFile FromOpenCv(const cv::FileNode& root, const std::string& file) {
  const cv::FileNode matrix = FirstOf(root, {"camera_matrix", "cameraMatrix", "K"});
  if (matrix.empty())
    throw InputError(file + ": no camera_matrix (nor cameraMatrix, K): not a camera file this tool reads");
  int width = static_cast<int>(root["image_width"].real()), height = static_cast<int>(root["image_height"].real());
  if (const cv::FileNode size = FirstOf(root, {"image_size", "imageSize"}); !size.empty()) {
    const auto wh = Numbers(size, file);
    if (wh.size() == 2) width = static_cast<int>(wh[0]), height = static_cast<int>(wh[1]);
  }
  if (width <= 0 || height <= 0)
    throw InputError(file + ": no image size (image_width and image_height, or image_size [w, h])");
  CameraFile out{FromMatrix(Numbers(matrix, file), width, height, file + ": " + matrix.name()), "OpenCV FileStorage"};
  if (const cv::FileNode d = FirstOf(root, {"distortion_coefficients", "dist_coeffs", "distCoeffs", "D"}); !d.empty())
    out.intrinsics.distortion = BrownConrady(Numbers(d, file), file + ": " + d.name());
  if (const cv::FileNode s = FirstOf(root, {"std_deviations_intrinsics", "stdDeviationsIntrinsics"}); !s.empty()) {
    const auto sigma = Numbers(s, file);
    if (sigma.size() < 4) throw InputError(file + ": " + s.name() + ": expected fx fy cx cy [k1 k2 p1 p2 k3 ...]");
    std::copy_n(sigma.begin(), std::min<std::size_t>(sigma.size(), 9), out.intrinsics.stddev.begin());
    out.has_stddev = true;
  }
  return out;
}

CameraFile FromKalibr(const cv::FileNode& root, const std::string& file, std::string camera) {
  std::vector<std::string> cameras;
  for (const auto& name : root.keys())
    if (std::regex_match(name, std::regex("cam[0-9]+"))) cameras.push_back(name);
  if (camera.empty() && cameras.size() == 1) camera = cameras.front();
  if (camera.empty() || root[camera].empty())
    throw InputError(fmt::format("{}: holds {}; name one, e.g. {}#{}", file, fmt::join(cameras, ", "), file,
                                 cameras.empty() ? "cam0" : cameras.front()));
  const cv::FileNode cam = root[camera];
  const std::string where = file + "#" + camera;
  const std::string model = cam["camera_model"], lens = cam["distortion_model"];
  if (model != "pinhole") throw InputError(where + ": camera_model " + model + " (this tool reads pinhole cameras)");
  if (lens != "radtan" && lens != "none")
    throw InputError(where + ": distortion_model " + lens + " is not a Brown-Conrady lens (radtan)");
  const auto k = Numbers(cam["intrinsics"], where), size = Numbers(cam["resolution"], where);
  if (k.size() != 4 || size.size() != 2)
    throw InputError(where + ": expected intrinsics [fu, fv, pu, pv] and resolution [w, h]");
  CameraFile out{
      FromMatrix({k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1}, static_cast<int>(size[0]), static_cast<int>(size[1]), where),
      "Kalibr camchain"};
  if (lens == "radtan")
    out.intrinsics.distortion = BrownConrady(Numbers(cam["distortion_coeffs"], where), where + ": distortion_coeffs");
  return out;
}

CameraFile FromMrcal(const std::string& text, const std::string& file) {
  const nlohmann::json model = PythonLiteralToJson(text, file);
  if (!model.is_object() || !model.contains("intrinsics") || !model.contains("imagersize"))
    throw InputError(file + ": expected an mrcal model with lensmodel, intrinsics and imagersize");
  const std::string lens = model.value("lensmodel", "");
  const std::map<std::string, std::size_t> terms = {
      {"LENSMODEL_PINHOLE", 0}, {"LENSMODEL_OPENCV4", 4}, {"LENSMODEL_OPENCV5", 5}};
  if (!terms.count(lens))
    throw InputError(file + ": lensmodel " + lens +
                     " (this tool reads LENSMODEL_PINHOLE, LENSMODEL_OPENCV4 and LENSMODEL_OPENCV5)");
  const auto k = model["intrinsics"].get<std::vector<double>>();
  const auto size = model["imagersize"].get<std::vector<int>>();
  if (k.size() != 4 + terms.at(lens) || size.size() != 2)
    throw InputError(fmt::format("{}: {} takes {} intrinsics and imagersize [w, h]", file, lens, 4 + terms.at(lens)));
  CameraFile out{FromMatrix({k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1}, size[0], size[1], file), "mrcal"};
  out.intrinsics.distortion = BrownConrady({k.begin() + 4, k.end()}, file + ": intrinsics");
  return out;
}

// OpenCV's YAML reader wants its "%YAML:1.0" directive, and a block
// sequence indented deeper than its key; PyYAML (Kalibr) writes it at the
// key's own indentation, which is valid YAML. Both are added.
std::string ForOpenCv(const std::string& text) {
  std::istringstream in(text);
  std::string out = "%YAML:1.0\n---\n", line;
  int key_indent = -1, shift_below = -1;  // the last bare key's indentation; lines from this one on move right
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(' ');
    if (first == std::string::npos || line[first] == '#') continue;
    const int indent = static_cast<int>(first);
    const bool item = line[first] == '-' && (first + 1 == line.size() || line[first + 1] == ' ');
    if (shift_below >= 0 && (indent < shift_below || (indent == shift_below && !item))) shift_below = -1;
    if (item && indent == key_indent && shift_below < 0) shift_below = indent;
    if (shift_below >= 0) line.insert(0, 2, ' ');
    const auto last = line.find_last_not_of(' ');
    key_indent = !item && line[last] == ':' ? indent : -1;
    out += line + "\n";
  }
  return out;
}

}  // namespace

CameraFile ReadCameraFile(const std::string& spec) {
  std::string file = spec, camera;
  if (std::smatch m; std::regex_match(spec, m, std::regex("(.*)#(cam[0-9]+)"))) file = m[1], camera = m[2];
  const fs::path path(file);
  const std::string text = ReadText(path);
  CameraFile out;
  if (path.extension() == ".cameramodel") {
    out = FromMrcal(text, file);
  } else {
    try {
      const bool xml = text.find("<opencv_storage>") != std::string::npos;
      const bool opencv_yaml = text.rfind("%YAML", 0) == 0;
      cv::FileStorage storage(xml || opencv_yaml ? text : ForOpenCv(text),
                              cv::FileStorage::READ | cv::FileStorage::MEMORY);
      const cv::FileNode root = storage.root();
      if (!root.isMap()) throw InputError(file + ": expected a map of keys (YAML or XML)");
      if (!camera.empty() || !root["cam0"].empty()) {
        out = FromKalibr(root, file, camera);
      } else if (root["camera_matrix"].isMap() && root["camera_matrix"]["dt"].empty() && !root["image_width"].empty()) {
        out = FromRos(root, file);
      } else {
        out = FromOpenCv(root, file);
      }
    } catch (const cv::Exception& e) {
      throw InputError(fmt::format("{}: not a YAML or XML camera file OpenCV can read ({})", file, e.err));
    }
  }
  out.intrinsics = CheckedIntrinsics(out.intrinsics, spec);
  return out;
}

}  // namespace speckle::formats
