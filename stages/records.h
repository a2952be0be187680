#pragma once
#include <limits>
// The typed records that flow between stages. A stage is a pure function
// RunX(const XOptions&, const XInput&) returning its record or a Rejection
// that says why the frame was not used; the pipeline counts and reports
// rejections, it never stops on one.
//
// Frames and units ride in names: `raw` is an 11-bit raw depth value, `_m`
// metres, `_px` pixels; `depth_from_colour` maps colour-camera coordinates to
// depth-camera coordinates. Normalized coordinates (x, y) are undistorted
// x/z, y/z in the camera named.
#include <Eigen/Geometry>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "schemas/depth_reading.h"

namespace speckle {

struct Rejection {
  std::string stage;
  std::string reason;
};

// Why a step that reads depth passes a frame by when it has none: a board
// frame with colour alone (a toolbox folder's extra chessboard views) still
// calibrates the colour camera, and the pipeline does not count it rejected.
inline constexpr const char* kNoDepthImage = "no depth image in this frame";

template <typename T>
using StageResult = std::variant<T, Rejection>;

template <typename T>
bool Accepted(const StageResult<T>& r) {
  return std::holds_alternative<T>(r);
}

// The chessboard a session was recorded with.
struct BoardGeometry {
  int squares_x = 11, squares_y = 8;
  double square_size_m = 0.0223;
  cv::Size InteriorCorners() const { return {squares_x - 1, squares_y - 1}; }
  double Width() const { return squares_x * square_size_m; }
  double Height() const { return squares_y * square_size_m; }
  // Interior corners in board coordinates (metres, z = 0), row-major.
  std::vector<cv::Point3f> InteriorCornerPoints() const;
};

struct ChessboardDetection {
  std::vector<cv::Point2f> corners;  // interior corners, row-major from board square (0, 0)
  cv::Size image_size;
  // The same corners as the refinement's other admissible windows placed
  // them. Where they disagree, the corners share an error that their scatter
  // cannot show (small squares behind a blurring lens), and the pose
  // inherits it.
  std::vector<std::vector<cv::Point2f>> other_refinements;
};

struct CameraIntrinsics {
  cv::Size image_size;
  cv::Matx33d camera_matrix = cv::Matx33d::eye();
  std::array<double, 5> distortion{};  // k1, k2, p1, p2, k3
  double rms_reprojection_px = 0;
  std::array<double, 9> stddev{};  // fx, fy, cx, cy, k1, k2, p1, p2, k3
  // The same terms' 9 x 9 covariance, row-major, where the fit that made the
  // camera states it (the joint calibration, the outline step); empty otherwise. The lens terms
  // are strongly correlated: their sigmas alone overstate what a pixel's ray
  // is known to many times over in the image's corners.
  std::vector<double> covariance;
  int views = 0;
  std::vector<double> per_view_error_px;

  Eigen::Vector2d Undistort(const Eigen::Vector2d& pixel) const;  // -> normalized (x, y)
  Eigen::Vector2d Project(const Eigen::Vector3d& point) const;    // camera coords -> pixel
};

// What the joint calibration (lab/joint/joint_calibration.h) fitted, when it
// refined the cameras: each kind of observation with its count and scatter,
// and the camera terms it held.
struct JointAccount {
  struct Term {
    std::string kind, unit;
    int observations = 0;
    double rms = 0;  // the kind's weight; its scatter only where there are observations
    // "0.159 px rms", or "none" where there was nothing to scatter.
    std::string Scatter() const;
  };
  std::vector<Term> terms;
  std::vector<std::string> held;
  // Camera terms an effect's parameters more than double the sigma of: "depth cx ± 6.0 is ± 1.7 with E's parameters
  // known".
  std::vector<std::string> trades;
  int iterations = 0;
  double seconds = 0;
};

struct CameraCalibration {
  CameraIntrinsics colour;
  CameraIntrinsics depth;  // the IR camera's geometry, which depth images share
  Eigen::Isometry3d depth_from_colour = Eigen::Isometry3d::Identity();
  // "session", "ir_chessboard", "ir_chessboard+depth_outlines" (refined
  // jointly with the outlines), "depth_outlines", "joint_board_planes", "nominal"
  std::string depth_intrinsics_source;
  // Said when the depth camera could not come from the data: what was used
  // instead and why. Empty otherwise.
  std::string depth_intrinsics_warning;
  // With extrinsics from the outlines: how far outside the board's edge the
  // depth step lies (px), fitted with them.
  std::optional<double> depth_edge_offset_px;
  double extrinsics_rms_px = 0;  // outline corners, depth image
  Eigen::Vector3d extrinsics_translation_sigma_m = Eigen::Vector3d::Zero();
  std::optional<double> depth_delay_s;  // depth exposure after colour, when a moving board showed it
  int extrinsics_views = 0;
  // Set when the joint calibration refined both cameras and the extrinsics
  // from every observation; their values and sigmas are then its.
  std::optional<JointAccount> joint;
  // A camera the session gave with standard deviations: the joint
  // calibration holds it to these values by them (a Gaussian prior; a term
  // of sigma 0 exactly). Read from session.json, not written with the cameras.
  std::optional<CameraIntrinsics> colour_prior, depth_prior;
};

// The board's outline found in a depth image: its four outer corners, in the
// order of the board's outline corners (0,0), (W,0), (W,H), (0,H).
struct DepthboardQuad {
  std::array<Eigen::Vector2d, 4> corners_px;
  double board_raw_median = 0;
  int board_pixels = 0;
  double line_fit_rms_px = 0;  // scatter of edge pixels about the fitted sides
};

// What kind of board point a sample was taken at.
enum class SamplePoint { kInteriorCorner = 0, kSquareCentre = 1, kBoardPlanePixel = 2 };

// One raw value paired with its true depth and every covariate the
// diagnostics may need.
struct PairedSample {
  int frame = 0;
  int pose = 0;         // still pose (frames of a still board share it)
  double time_s = 0;    // since the recording started
  double u = 0, v = 0;  // depth pixel
  double x = 0, y = 0;  // normalized undistorted depth coordinates
  double raw = 0;       // robust local raw value
  double depth_m = 0;   // z of the board point in the depth camera, from the colour pose
  // Standard deviation of depth_m from the colour pose's uncertainty (NaN:
  // not known). Poses scatter by this much however good the depth model is.
  double truth_sigma_m = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d in_colour = Eigen::Vector3d::Zero();  // the board point in colour-camera coordinates
  double tilt_deg = 0;                                  // board normal vs the depth camera's axis
  double gradient_u = 0, gradient_v = 0;                // local raw-value gradient (raw units per depth pixel)
  double albedo = 0.5;   // the board's IR albedo in the raw value's window: 0 all dark squares, 1 all light
  double motion_px = 0;  // colour corners' motion since the previous frame
  // The board's image velocity (colour pixels per second, still poses only):
  // with the gradient it gives how fast this point's raw value changes.
  double velocity_u = 0, velocity_v = 0;
  // How fast this board point's raw value changes (raw units per second;
  // for the joint calibration's samples, the raw value at its pixel), from
  // the same board point in the neighbouring depth frames (see
  // stages/raw_rate.h); 0 where no neighbour shows it. Depth exposed at
  // another instant than colour reads the raw value moved by this times the
  // delay.
  double raw_rate = 0;
  int board_point = -1;  // which point of the board (the same in every frame of a pose)
  // Set by the fit, not stored: the raw value the base form alone predicts
  // for the true depth. Effects read it as their raw covariate while fitting,
  // because the measured raw value carries the noise, and an effect that
  // scales with a noisy covariate would absorb noise and look better than it is.
  double fit_raw = std::numeric_limits<double>::quiet_NaN();
  SamplePoint point = SamplePoint::kInteriorCorner;
};

}  // namespace speckle
