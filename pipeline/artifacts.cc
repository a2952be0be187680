#include "pipeline/artifacts.h"

#include <H5Cpp.h>
#include <openssl/evp.h>

#include <fstream>
#include <random>
#include <regex>

#include "recorder/h5_access.h"
#include "schemas/atomic_file.h"
#include "schemas/errors.h"
#include "schemas/session_manifest.h"
#include "speckle/tool_version.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

nlohmann::json StatsJson(const ResidualStats& s) {
  return {{"count", s.count}, {"mean", s.mean}, {"sigma", s.sigma}, {"rms", s.rms},
          {"p05", s.p05},     {"p50", s.p50},   {"p95", s.p95},     {"max_abs", s.max_abs}};
}

nlohmann::json IntrinsicsJson(const CameraIntrinsics& c) {
  return {{"image_size", {c.image_size.width, c.image_size.height}},
          {"fx", c.camera_matrix(0, 0)}, {"fy", c.camera_matrix(1, 1)},
          {"cx", c.camera_matrix(0, 2)}, {"cy", c.camera_matrix(1, 2)},
          {"distortion_k1_k2_p1_p2_k3", c.distortion},
          {"stddev_fx_fy_cx_cy_k1_k2_p1_p2_k3", c.stddev},
          {"rms_reprojection_px", c.rms_reprojection_px}, {"views", c.views}};
}

nlohmann::json FitJson(const NamedFit& f) {
  const auto& info = model::Info(f.fit.form);
  nlohmann::json parameters = nlohmann::json::array();
  for (std::size_t i = 0; i < f.fit.parameters.size(); ++i) {
    parameters.push_back({{"name", info.parameters[i]}, {"unit", info.units[i]}, {"value", f.fit.parameters[i]},
                          {"sigma", f.fit.sigma[i]}, {"sigma_from_samples", f.fit.sigma_samples[i]},
                          {"sigma_from_cameras", f.fit.sigma_cameras[i]}});
  }
  return {{"name", f.name},
          {"base_form", info.name},
          {"undistortion", f.undistorted},
          {"parameters", parameters},
          {"covariance", f.fit.covariance},
          {"converged", f.fit.converged},
          {"residual_raw", StatsJson(f.fit.raw)},
          {"residual_mm", StatsJson(f.fit.depth_mm)},
          {"held_out_raw", StatsJson(f.fit.held_out_raw)},
          {"held_out_mm", StatsJson(f.fit.held_out_mm)}};
}

struct Column {
  const char* name;
  double PairedSample::*field;
};
constexpr Column kColumns[] = {{"time_s", &PairedSample::time_s}, {"u", &PairedSample::u},
                               {"v", &PairedSample::v},           {"x", &PairedSample::x},
                               {"y", &PairedSample::y},           {"raw", &PairedSample::raw},
                               {"depth_m", &PairedSample::depth_m}, {"tilt_deg", &PairedSample::tilt_deg},
                               {"gradient", &PairedSample::gradient}, {"albedo", &PairedSample::albedo},
                               {"motion_px", &PairedSample::motion_px}};

void CheckSchema(const H5::H5File& file, const std::string& where, const std::string& name, int version) {
  const std::string schema = h5::ReadStringAttribute(file, "schema", where);
  if (schema != name) throw InputError(where + ": attribute 'schema' is \"" + schema + "\", expected \"" + name + "\"");
  const long long found = h5::ReadIntAttribute(file, "schema_version", where);
  if (found != version) {
    throw SchemaVersionError(where + ": " + name + " schema version " + std::to_string(found) +
                             " is not understood (this tool reads version " + std::to_string(version) + ")");
  }
}

template <typename T>
void WriteVector(H5::Group& group, const std::string& name, const std::vector<T>& values, const H5::PredType& type,
                 const std::vector<hsize_t>& dims) {
  const H5::DataSpace space(static_cast<int>(dims.size()), dims.data());
  group.createDataSet(name, type, space).write(values.data(), type);
}

template <typename T>
std::vector<T> ReadVector(const H5::H5File& file, const std::string& name, const H5::PredType& type,
                          const std::string& where) {
  if (!h5::Exists(file, name)) throw InputError(where + ": missing dataset /" + name);
  const H5::DataSet d = file.openDataSet(name);
  std::size_t n = 1;
  for (hsize_t dim : h5::Dimensions(d)) n *= dim;
  std::vector<T> values(n);
  if (n) d.read(values.data(), type);
  return values;
}

}  // namespace

std::string Sha256File(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open to hash");
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr);
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    EVP_DigestUpdate(ctx, buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx, digest, &length);
  EVP_MD_CTX_free(ctx);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned i = 0; i < length; ++i) hex += {kHex[digest[i] >> 4], kHex[digest[i] & 15]};
  return hex;
}

nlohmann::json CalibrationJson(const CalibrationRun& run, const fs::path& session_dir) {
  const PipelineResult& p = run.pipeline;
  nlohmann::json inputs = nlohmann::json::array();
  const SessionManifest manifest = ReadSessionManifest(session_dir);
  inputs.push_back({{"file", kSessionFileName}, {"sha256", Sha256File(session_dir / kSessionFileName)}});
  for (const auto& r : manifest.recordings) {
    inputs.push_back({{"file", r.file}, {"purpose", ToString(r.purpose)}, {"sha256", Sha256File(session_dir / r.file)}});
  }
  const NamedFit& chosen = run.Chosen();
  const Eigen::Isometry3d& e = p.cameras.depth_from_colour;
  const Eigen::AngleAxisd rotation(e.linear());
  return {
      {"schema", "speckle.calibration"},
      {"schema_version", kCalibrationSchemaVersion},
      {"tool_version", kToolVersion},
      {"created_utc", UtcNowIso8601()},
      {"session", {{"path", fs::absolute(session_dir).string()}, {"inputs", inputs}}},
      {"model_spec", ToJson(run.spec)},
      {"model", FitJson(chosen)},
      {"undistortion_grid", chosen.undistorted ? nlohmann::json("undistortion_grid.h5") : nlohmann::json(nullptr)},
      {"samples", "samples.h5"},
      {"cameras",
       {{"colour", IntrinsicsJson(p.cameras.colour)},
        {"depth", IntrinsicsJson(p.cameras.depth)},
        {"depth_intrinsics_source", p.cameras.depth_intrinsics_source},
        {"depth_from_colour",
         {{"rotation_axis_angle_rad", rotation.axis() * rotation.angle()},
          {"translation_m", e.translation()},
          {"translation_sigma_m", p.cameras.extrinsics_translation_sigma_m},
          {"outline_rms_px", p.cameras.extrinsics_rms_px},
          {"views", p.cameras.extrinsics_views}}}}},
      {"metrics",
       {{"samples", p.samples.size()},
        {"board_frames", p.board_frames},
        {"paired_frames", p.paired_frames},
        {"paired_share", p.board_frames ? double(p.paired_frames) / p.board_frames : 0.0},
        {"residual_raw", StatsJson(chosen.fit.raw)},
        {"residual_mm", StatsJson(chosen.fit.depth_mm)},
        {"held_out_raw", StatsJson(chosen.fit.held_out_raw)},
        {"held_out_mm", StatsJson(chosen.fit.held_out_mm)},
        {"wall_sigma_reduction", run.wall_sigma_reduction}}},
  };
}

nlohmann::json ReportJson(const CalibrationRun& run) {
  const PipelineResult& p = run.pipeline;
  nlohmann::json fits = nlohmann::json::array();
  for (const auto& f : run.fits) fits.push_back(FitJson(f));
  std::map<std::string, int> rejection_counts;
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& f : p.frames) {
    nlohmann::json j = {{"recording", f.recording}, {"index", f.index}, {"source_number", f.source_number},
                        {"pose", f.pose}, {"samples", f.samples}};
    if (f.rejection) {
      j["rejected_by"] = f.rejection->stage;
      j["reason"] = f.rejection->reason;
      ++rejection_counts[f.recording + " / " + f.rejection->stage + ": " + f.rejection->reason];
    }
    frames.push_back(j);
  }
  nlohmann::json rejections = nlohmann::json::array();
  for (const auto& [reason, count] : rejection_counts) rejections.push_back({{"reason", reason}, {"frames", count}});
  nlohmann::json snapshots = nlohmann::json::array();
  for (const auto& s : p.snapshots) {
    snapshots.push_back({{"frame", s.frame}, {"valid_pixels", s.valid_pixels}, {"inlier_pixels", s.inlier_pixels},
                         {"true_raw",
                          {{"image_minimum", s.true_raw_image_min}, {"hyperboloid", s.true_raw_hyperboloid},
                           {"centre_minimum", s.true_raw_centre_min}}},
                         {"fit_sigma_raw", s.fit_sigma_raw}, {"raw_sigma", s.raw_sigma_before}});
  }
  nlohmann::json walls = nlohmann::json::array();
  for (const auto& w : run.walls) {
    walls.push_back({{"frame", w.snapshot_frame}, {"true_raw", w.true_raw}, {"sigma_before_raw", w.sigma_before},
                     {"sigma_after_raw_held_out", w.sigma_after}});
  }
  nlohmann::json timings = nlohmann::json::array();
  for (const auto& t : p.timings) timings.push_back({{"stage", t.stage}, {"seconds", t.seconds}, {"calls", t.calls}});
  return {
      {"schema", "speckle.report"},
      {"schema_version", kReportSchemaVersion},
      {"tool_version", kToolVersion},
      {"chosen_model", run.Chosen().name},
      {"fits", fits},
      {"frames", frames},
      {"rejections", rejections},
      {"planar_snapshots", snapshots},
      {"undistortion",
       p.grid ? nlohmann::json{{"supported_share", p.grid->SupportedShare()},
                               {"true_raw_method", ToString(p.grid->method)},
                               {"wall_sigma_reduction_held_out", run.wall_sigma_reduction},
                               {"walls", walls}}
              : nlohmann::json{{"absent_because", p.grid_rejection ? p.grid_rejection->reason : ""}}},
      {"stage_seconds", timings},
      {"wall_seconds", p.wall_seconds},
  };
}

void WriteSamples(const fs::path& path, const std::vector<PairedSample>& samples) {
  H5::H5File file(path.string(), H5F_ACC_EXCL);
  h5::WriteStringAttribute(file, "schema", "speckle.samples");
  h5::WriteIntAttribute(file, "schema_version", kSamplesSchemaVersion);
  H5::Group root = file.openGroup("/");
  const std::vector<hsize_t> dims{samples.size()};
  for (const Column& c : kColumns) {
    std::vector<double> values;
    for (const auto& s : samples) values.push_back(s.*c.field);
    WriteVector(root, c.name, values, H5::PredType::NATIVE_DOUBLE, dims);
  }
  std::vector<double> in_colour;
  for (const auto& s : samples) in_colour.insert(in_colour.end(), s.in_colour.data(), s.in_colour.data() + 3);
  WriteVector(root, "in_colour_m", in_colour, H5::PredType::NATIVE_DOUBLE, {samples.size(), 3});
  std::vector<int> frame, pose, point;
  for (const auto& s : samples) {
    frame.push_back(s.frame), pose.push_back(s.pose), point.push_back(static_cast<int>(s.point));
  }
  WriteVector(root, "frame", frame, H5::PredType::NATIVE_INT, dims);
  WriteVector(root, "pose", pose, H5::PredType::NATIVE_INT, dims);
  WriteVector(root, "point", point, H5::PredType::NATIVE_INT, dims);
}

std::vector<PairedSample> ReadSamples(const fs::path& path) {
  h5::SilenceLibraryErrors();
  const std::string where = path.string();
  if (!fs::exists(path)) throw InputError(where + ": no cached samples (run run-pipeline first)");
  try {
    const H5::H5File file(where, H5F_ACC_RDONLY);
    CheckSchema(file, where, "speckle.samples", kSamplesSchemaVersion);
    const auto frame = ReadVector<int>(file, "frame", H5::PredType::NATIVE_INT, where);
    std::vector<PairedSample> samples(frame.size());
    for (const Column& c : kColumns) {
      const auto values = ReadVector<double>(file, c.name, H5::PredType::NATIVE_DOUBLE, where);
      if (values.size() != samples.size()) throw InputError(where + ": dataset /" + c.name + " has the wrong length");
      for (std::size_t i = 0; i < samples.size(); ++i) samples[i].*c.field = values[i];
    }
    const auto in_colour = ReadVector<double>(file, "in_colour_m", H5::PredType::NATIVE_DOUBLE, where);
    if (in_colour.size() != 3 * samples.size()) throw InputError(where + ": dataset /in_colour_m has the wrong length");
    for (std::size_t i = 0; i < samples.size(); ++i) samples[i].in_colour = Eigen::Vector3d::Map(&in_colour[3 * i]);
    const auto pose = ReadVector<int>(file, "pose", H5::PredType::NATIVE_INT, where);
    const auto point = ReadVector<int>(file, "point", H5::PredType::NATIVE_INT, where);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      samples[i].frame = frame[i];
      samples[i].pose = pose.at(i);
      samples[i].point = static_cast<SamplePoint>(point.at(i));
    }
    return samples;
  } catch (const H5::Exception& e) {
    throw InputError(where + ": unreadable samples: " + e.getDetailMsg());
  }
}

void WriteGrid(const fs::path& path, const UndistortionGrid& g) {
  H5::H5File file(path.string(), H5F_ACC_EXCL);
  h5::WriteStringAttribute(file, "schema", "speckle.undistortion_grid");
  h5::WriteIntAttribute(file, "schema_version", kGridSchemaVersion);
  h5::WriteStringAttribute(file, "true_raw_method", ToString(g.method));
  h5::WriteStringAttribute(file, "meaning",
                           "r' = raw + correction(raw, y, x), trilinear; x, y normalized undistorted depth coordinates, "
                           "cells evenly spaced over [x_min, x_max] x [y_min, y_max]");
  H5::Group root = file.openGroup("/");
  WriteVector(root, "raw_nodes", g.raw_nodes, H5::PredType::NATIVE_DOUBLE, {g.raw_nodes.size()});
  WriteVector(root, "extent_x_min_x_max_y_min_y_max", std::vector<double>{g.x_min, g.x_max, g.y_min, g.y_max},
              H5::PredType::NATIVE_DOUBLE, {4});
  const std::vector<hsize_t> dims{g.raw_nodes.size(), hsize_t(g.ny), hsize_t(g.nx)};
  WriteVector(root, "correction", g.correction, H5::PredType::NATIVE_FLOAT, dims);
  WriteVector(root, "std_error", g.std_error, H5::PredType::NATIVE_FLOAT, dims);
  WriteVector(root, "supported", g.supported, H5::PredType::NATIVE_UINT8, dims);
}

UndistortionGrid ReadGrid(const fs::path& path) {
  h5::SilenceLibraryErrors();
  const std::string where = path.string();
  if (!fs::exists(path)) throw InputError(where + ": no undistortion grid");
  try {
    const H5::H5File file(where, H5F_ACC_RDONLY);
    CheckSchema(file, where, "speckle.undistortion_grid", kGridSchemaVersion);
    UndistortionGrid g;
    g.raw_nodes = ReadVector<double>(file, "raw_nodes", H5::PredType::NATIVE_DOUBLE, where);
    const auto extent = ReadVector<double>(file, "extent_x_min_x_max_y_min_y_max", H5::PredType::NATIVE_DOUBLE, where);
    if (extent.size() != 4) throw InputError(where + ": extent must hold 4 numbers");
    g.x_min = extent[0], g.x_max = extent[1], g.y_min = extent[2], g.y_max = extent[3];
    const auto dims = h5::Dimensions(file.openDataSet("correction"));
    if (dims.size() != 3 || dims[0] != g.raw_nodes.size()) throw InputError(where + ": /correction has the wrong shape");
    g.ny = static_cast<int>(dims[1]);
    g.nx = static_cast<int>(dims[2]);
    g.correction = ReadVector<float>(file, "correction", H5::PredType::NATIVE_FLOAT, where);
    g.std_error = ReadVector<float>(file, "std_error", H5::PredType::NATIVE_FLOAT, where);
    g.supported = ReadVector<std::uint8_t>(file, "supported", H5::PredType::NATIVE_UINT8, where);
    return g;
  } catch (const H5::Exception& e) {
    throw InputError(where + ": unreadable grid: " + e.getDetailMsg());
  }
}

fs::path WriteCalibrationVersion(const fs::path& session_dir, const CalibrationRun& run) {
  const fs::path root = session_dir / "calibrations";
  fs::create_directories(root);
  std::random_device entropy;
  const fs::path temp = root / (".incoming-" + std::to_string(entropy()));
  fs::create_directory(temp);
  try {
    WriteFileAtomically(temp / "calibration.json", CalibrationJson(run, session_dir).dump(2) + "\n");
    WriteFileAtomically(temp / "report.json", ReportJson(run).dump(2) + "\n");
    WriteSamples(temp / "samples.h5", run.pipeline.samples);
    if (run.pipeline.grid) WriteGrid(temp / "undistortion_grid.h5", *run.pipeline.grid);
    SyncPath(temp);
    // The next free version number; a concurrent run that takes it first
    // makes the rename fail, and we try the one after.
    static const std::regex kVersion(R"(v(\d{4,}))");
    int next = 1;
    for (const auto& entry : fs::directory_iterator(root)) {
      std::smatch m;
      const std::string name = entry.path().filename().string();
      if (std::regex_match(name, m, kVersion)) next = std::max(next, std::stoi(m[1]) + 1);
    }
    for (int attempt = 0; attempt < 100; ++attempt, ++next) {
      char name[16];
      std::snprintf(name, sizeof name, "v%04d", next);
      const fs::path target = root / name;
      if (fs::exists(target)) continue;
      std::error_code ec;
      fs::rename(temp, target, ec);
      if (!ec) {
        SyncPath(root);
        return target;
      }
    }
    throw std::runtime_error("could not claim a version directory under " + root.string());
  } catch (...) {
    std::error_code ignored;
    fs::remove_all(temp, ignored);
    throw;
  }
}

}  // namespace speckle
