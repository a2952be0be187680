#include "pipeline/samples_file.h"

#include <H5Cpp.h>
#include <fmt/format.h>

#include <cmath>

#include "schemas/artifact_schema.h"
#include "schemas/errors.h"
#include "schemas/h5_access.h"

namespace speckle {
namespace {

namespace fs = std::filesystem;

struct Column {
  const char* name;
  double PairedSample::*field;
  int since = 2;  // the samples schema version that added it; older files leave the field at its default
};
constexpr Column kColumns[] = {{"time_s", &PairedSample::time_s},
                               {"u", &PairedSample::u},
                               {"v", &PairedSample::v},
                               {"x", &PairedSample::x},
                               {"y", &PairedSample::y},
                               {"raw", &PairedSample::raw},
                               {"depth_m", &PairedSample::depth_m},
                               {"tilt_deg", &PairedSample::tilt_deg},
                               {"gradient_u", &PairedSample::gradient_u},
                               {"gradient_v", &PairedSample::gradient_v},
                               {"albedo", &PairedSample::albedo},
                               {"motion_px", &PairedSample::motion_px},
                               {"velocity_u", &PairedSample::velocity_u},
                               {"velocity_v", &PairedSample::velocity_v},
                               {"truth_sigma_m", &PairedSample::truth_sigma_m, 3},  // default NaN: unknown
                               {"raw_rate", &PairedSample::raw_rate, 4}};           // default 0: a still board

// A true depth and a raw value no sensor gives would be fitted as data, and
// a verdict drawn from them (inf depths read as "as good as the cameras allow").
void RequirePositive(const std::vector<PairedSample>& samples, const std::string& where) {
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!(samples[i].depth_m > 0))
      throw InputError(fmt::format("{}: /depth_m of sample {} is {}, not a depth", where, i, samples[i].depth_m));
    if (!(samples[i].raw > 0))
      throw InputError(fmt::format("{}: /raw of sample {} is {}, not a reading", where, i, samples[i].raw));
  }
}

void WriteBoardFrames(H5::H5File& file, const std::vector<joint::BoardFrame>& frames) {
  H5::Group group = file.createGroup("board_frames");
  std::vector<int> frame, pose, corner_count, has_quad;
  std::vector<double> colour_from_board, velocity, corners, quad_corners, quad_stats;
  for (const auto& f : frames) {
    frame.push_back(f.frame), pose.push_back(f.pose);
    const Eigen::Matrix4d m = f.colour_from_board.matrix();
    colour_from_board.insert(colour_from_board.end(), m.data(), m.data() + 16);
    velocity.insert(velocity.end(), f.board_velocity.data(), f.board_velocity.data() + 3);
    corner_count.push_back(static_cast<int>(f.colour_corners.size()));
    for (const auto& c : f.colour_corners) corners.push_back(c.x), corners.push_back(c.y);
    has_quad.push_back(f.quad.has_value());
    const DepthboardQuad q = f.quad.value_or(DepthboardQuad{});
    for (const auto& c : q.corners_px) quad_corners.push_back(c.x()), quad_corners.push_back(c.y());
    quad_stats.insert(quad_stats.end(), {q.board_raw_median, static_cast<double>(q.board_pixels), q.line_fit_rms_px});
  }
  const hsize_t n = frames.size();
  h5::WriteVector(group, "frame", frame, H5::PredType::NATIVE_INT, {n});
  h5::WriteVector(group, "pose", pose, H5::PredType::NATIVE_INT, {n});
  h5::WriteVector(group, "colour_from_board", colour_from_board, H5::PredType::NATIVE_DOUBLE, {n, 16});
  h5::WriteVector(group, "board_velocity_m_s", velocity, H5::PredType::NATIVE_DOUBLE, {n, 3});
  h5::WriteVector(group, "corner_count", corner_count, H5::PredType::NATIVE_INT, {n});
  h5::WriteVector(group, "colour_corners_px", corners, H5::PredType::NATIVE_DOUBLE, {corners.size() / 2, 2});
  h5::WriteVector(group, "has_quad", has_quad, H5::PredType::NATIVE_INT, {n});
  h5::WriteVector(group, "quad_corners_px", quad_corners, H5::PredType::NATIVE_DOUBLE, {n, 8});
  h5::WriteVector(group, "quad_stats", quad_stats, H5::PredType::NATIVE_DOUBLE, {n, 3});
}

// Each dataset's length checked against the frames', every value finite.
std::vector<joint::BoardFrame> ReadBoardFrames(const H5::H5File& file, const std::string& where) {
  const auto doubles = [&](const std::string& name, std::size_t per_frame_or_zero, std::size_t n) {
    auto v = h5::ReadVector<double>(file, "board_frames/" + name, H5::PredType::NATIVE_DOUBLE, where);
    if (per_frame_or_zero && v.size() != per_frame_or_zero * n)
      throw InputError(fmt::format("{}: /board_frames/{} has {} values, not {} per frame", where, name, v.size(),
                                   per_frame_or_zero));
    for (double x : v)
      if (!std::isfinite(x)) throw InputError(fmt::format("{}: /board_frames/{} holds {}", where, name, x));
    return v;
  };
  const auto frame = h5::ReadVector<int>(file, "board_frames/frame", H5::PredType::NATIVE_INT, where);
  const std::size_t n = frame.size();
  const auto pose = h5::ReadVector<int>(file, "board_frames/pose", H5::PredType::NATIVE_INT, where);
  const auto count = h5::ReadVector<int>(file, "board_frames/corner_count", H5::PredType::NATIVE_INT, where);
  const auto has_quad = h5::ReadVector<int>(file, "board_frames/has_quad", H5::PredType::NATIVE_INT, where);
  if (pose.size() != n || count.size() != n || has_quad.size() != n)
    throw InputError(where + ": /board_frames/pose, corner_count and has_quad must have one entry per frame");
  const auto transform = doubles("colour_from_board", 16, n), velocity = doubles("board_velocity_m_s", 3, n);
  const auto quads = doubles("quad_corners_px", 8, n), stats = doubles("quad_stats", 3, n);
  const auto corners = doubles("colour_corners_px", 0, n);
  std::vector<joint::BoardFrame> out(n);
  std::size_t at = 0;
  for (std::size_t i = 0; i < n; ++i) {
    joint::BoardFrame& f = out[i];
    f.frame = frame[i], f.pose = pose[i];
    f.colour_from_board.matrix() = Eigen::Matrix4d::Map(&transform[16 * i]);
    f.board_velocity = Eigen::Vector3d::Map(&velocity[3 * i]);
    if (count[i] < 0 || at + 2 * static_cast<std::size_t>(count[i]) > corners.size())
      throw InputError(fmt::format("{}: /board_frames/corner_count of frame {} is {}: more corners than stored", where,
                                   f.frame, count[i]));
    for (int c = 0; c < count[i]; ++c, at += 2)
      f.colour_corners.emplace_back(static_cast<float>(corners[at]), static_cast<float>(corners[at + 1]));
    if (!has_quad[i]) continue;
    DepthboardQuad q;
    for (std::size_t c = 0; c < 4; ++c)
      q.corners_px[c] = Eigen::Vector2d(quads[8 * i + 2 * c], quads[8 * i + 2 * c + 1]);
    q.board_raw_median = stats[3 * i], q.board_pixels = static_cast<int>(stats[3 * i + 1]);
    q.line_fit_rms_px = stats[3 * i + 2];
    f.quad = q;
  }
  return out;
}

}  // namespace

void WriteSamples(const fs::path& path, const std::vector<PairedSample>& samples,
                  const DepthPerturbations& perturbations, const std::vector<joint::BoardFrame>& board_frames) {
  H5::H5File file(path.string(), H5F_ACC_EXCL);
  h5::WriteStringAttribute(file, "schema", "speckle.samples");
  h5::WriteIntAttribute(file, "schema_version", kSamplesSchemaVersion);
  H5::Group root = file.openGroup("/");
  const std::vector<hsize_t> dims{samples.size()};
  for (const Column& c : kColumns) {
    std::vector<double> values;
    for (const auto& s : samples) values.push_back(s.*c.field);
    h5::WriteVector(root, c.name, values, H5::PredType::NATIVE_DOUBLE, dims);
  }
  std::vector<double> in_colour;
  for (const auto& s : samples) in_colour.insert(in_colour.end(), s.in_colour.data(), s.in_colour.data() + 3);
  h5::WriteVector(root, "in_colour_m", in_colour, H5::PredType::NATIVE_DOUBLE, {samples.size(), 3});
  std::vector<int> frame, pose, point, board_point;
  for (const auto& s : samples) {
    frame.push_back(s.frame), pose.push_back(s.pose), point.push_back(static_cast<int>(s.point));
    board_point.push_back(s.board_point);
  }
  h5::WriteVector(root, "frame", frame, H5::PredType::NATIVE_INT, dims);
  h5::WriteVector(root, "pose", pose, H5::PredType::NATIVE_INT, dims);
  h5::WriteVector(root, "point", point, H5::PredType::NATIVE_INT, dims);
  h5::WriteVector(root, "board_point", board_point, H5::PredType::NATIVE_INT, dims);
  std::vector<double> moved;
  for (const auto& depths : perturbations.depths) moved.insert(moved.end(), depths.begin(), depths.end());
  h5::WriteVector(root, "perturbed_depth_m", moved, H5::PredType::NATIVE_DOUBLE,
                  {perturbations.size(), samples.size()});
  h5::WriteIntAttribute(file, "perturbations_in_floor",
                        static_cast<int>(std::min(perturbations.in_floor, perturbations.size())));
  if (!board_frames.empty()) WriteBoardFrames(file, board_frames);
}

CachedSamples ReadSamples(const fs::path& path) {
  const std::string where = path.string();
  return ReadArtifactH5(
      path, "speckle.samples", kSamplesSchemaVersion, 2, "no cached samples (run run-pipeline first)", "samples",
      [&](const H5::H5File& file, int version) {
        const auto frame = h5::ReadVector<int>(file, "frame", H5::PredType::NATIVE_INT, where);
        CachedSamples cached;
        std::vector<PairedSample>& samples = cached.samples;
        samples.resize(frame.size());
        for (const Column& c : kColumns) {
          if (version < c.since) continue;
          const auto values = h5::ReadVector<double>(file, c.name, H5::PredType::NATIVE_DOUBLE, where);
          if (values.size() != samples.size())
            throw InputError(where + ": dataset /" + c.name + " has the wrong length");
          for (std::size_t i = 0; i < samples.size(); ++i) {
            // NaN is truth_sigma_m's "unknown"; infinity is nothing a sample can hold.
            if (std::isinf(values[i]) || (std::isnan(values[i]) && c.field != &PairedSample::truth_sigma_m))
              throw InputError(fmt::format("{}: /{} of sample {} is {}", where, c.name, i, values[i]));
            samples[i].*c.field = values[i];
          }
        }
        RequirePositive(samples, where);
        const auto in_colour = h5::ReadVector<double>(file, "in_colour_m", H5::PredType::NATIVE_DOUBLE, where);
        if (in_colour.size() != 3 * samples.size())
          throw InputError(where + ": dataset /in_colour_m has the wrong length");
        for (std::size_t i = 0; i < samples.size(); ++i) samples[i].in_colour = Eigen::Vector3d::Map(&in_colour[3 * i]);
        const auto pose = h5::ReadVector<int>(file, "pose", H5::PredType::NATIVE_INT, where);
        const auto point = h5::ReadVector<int>(file, "point", H5::PredType::NATIVE_INT, where);
        const auto board_point = h5::ReadVector<int>(file, "board_point", H5::PredType::NATIVE_INT, where);
        if (pose.size() != samples.size() || point.size() != samples.size() || board_point.size() != samples.size())
          throw InputError(where + ": datasets /pose, /point and /board_point must have one entry per sample");
        for (std::size_t i = 0; i < samples.size(); ++i) {
          samples[i].frame = frame[i];
          samples[i].pose = pose[i];
          samples[i].point = static_cast<SamplePoint>(point[i]);
          samples[i].board_point = board_point[i];
        }
        const auto moved = h5::ReadVector<double>(file, "perturbed_depth_m", H5::PredType::NATIVE_DOUBLE, where);
        if (!samples.empty() && moved.size() % samples.size() != 0)
          throw InputError(where + ": /perturbed_depth_m must be [K, N] with N the number of samples");
        for (std::size_t i = 0; i < moved.size(); ++i)
          if (!(std::isfinite(moved[i]) && moved[i] > 0))
            throw InputError(fmt::format("{}: /perturbed_depth_m of sample {} (perturbation {}) is {}, not a depth",
                                         where, i % samples.size(), i / samples.size(), moved[i]));
        for (std::size_t k = 0; !samples.empty() && k < moved.size() / samples.size(); ++k)
          cached.perturbations.depths.emplace_back(moved.begin() + static_cast<long>(k * samples.size()),
                                                   moved.begin() + static_cast<long>((k + 1) * samples.size()));
        cached.perturbations.in_floor = cached.perturbations.size();
        if (version >= 5) {
          const long long in_floor = h5::ReadIntAttribute(file, "perturbations_in_floor", where);
          if (in_floor < 0 || static_cast<std::size_t>(in_floor) > cached.perturbations.size())
            throw InputError(where + ": attribute perturbations_in_floor is " + std::to_string(in_floor) +
                             ", not 0 to " + std::to_string(cached.perturbations.size()) + " (the perturbations)");
          cached.perturbations.in_floor = static_cast<std::size_t>(in_floor);
        }
        if (version >= 6 && h5::Exists(file, "board_frames")) cached.board_frames = ReadBoardFrames(file, where);
        return cached;
      });
}

}  // namespace speckle
