#include "epichead/vision/camera.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string_view>

#include <Eigen/LU>
#include <opencv2/core.hpp>

#include "camera_yaml_precheck.h"

namespace epichead::vision {
namespace {

using Error = std::unexpected<std::string>;

std::string shape(const cv::Mat& m) { return std::to_string(m.rows) + "x" + std::to_string(m.cols); }

// Reads a positive integer size field (image_width, image_height).
std::expected<int, std::string> read_size(const cv::FileStorage& fs, const std::string& path, const char* field) {
  const cv::FileNode node = fs[field];
  if (node.empty() || node.isNone()) return Error(path + ": missing field '" + field + "'");
  if (!node.isInt() && !node.isReal()) return Error(path + ": " + field + " must be a number");
  const double value = node.real();
  if (!std::isfinite(value) || value != std::floor(value))
    return Error(path + ": " + field + " must be a whole number of pixels");
  if (value <= 0 || value > 1e6) return Error(path + ": " + field + " must be positive (and sane), got " + std::to_string(value));
  return static_cast<int>(value);
}

// What an OpenCV exception says. Its YAML parser puts the reason ("(3): Invalid character", the
// file name being empty for text in memory) where the function name goes, and the function name
// ("parseValue") where the reason goes.
std::string opencv_reason(const cv::Exception& e) {
  const std::size_t at = e.func.find("): ");
  const std::size_t open = e.func.rfind('(', at);
  if (e.code != cv::Error::StsParseError || at == std::string::npos || open == std::string::npos) return e.err;
  return "line " + e.func.substr(open + 1, at - open - 1) + ": " + e.func.substr(at + 3);
}

// The largest matrix side a camera YAML has a use for (distortion: 14 values at most).
constexpr int kMaxMatrixSide = 16;

// Reads a whole-number matrix dimension (rows, cols) in 0..kMaxMatrixSide.
std::expected<int, std::string> read_dimension(const cv::FileNode& matrix, const std::string& path, const char* field,
                                               const char* dimension) {
  const cv::FileNode node = matrix[dimension];
  const std::string where = path + ": " + field + "." + dimension;
  if (node.empty() || node.isNone()) return Error(path + ": " + field + " is not a valid opencv-matrix (no " + dimension + ")");
  if (!node.isInt()) return Error(where + " must be a whole number");
  const int value = static_cast<int>(node);
  if (value < 0 || value > kMaxMatrixSide)
    return Error(where + " must be 0.." + std::to_string(kMaxMatrixSide) + ", got " + std::to_string(value));
  return value;
}

// Reads an opencv-matrix field (rows, cols, dt, data) as CV_64F. Decoded here rather than by
// OpenCV's `node >> mat`, which allocates rows x cols x element size before it looks at the
// data: a one-character typo in rows or cols asks it for tens of gigabytes.
// ros: a ROS camera_info file, whose matrices are plain maps {rows, cols, data} of doubles.
std::expected<cv::Mat, std::string> read_matrix(const cv::FileStorage& fs, const std::string& path, const char* field,
                                                bool ros) {
  const cv::FileNode node = fs[field];
  if (node.empty() || node.isNone()) return Error(path + ": missing field '" + field + "'");
  if (!node.isMap()) return Error(path + ": " + field + " must be an opencv-matrix (rows, cols, dt, data)");
  auto rows = read_dimension(node, path, field, "rows");
  if (!rows) return Error(rows.error());
  auto cols = read_dimension(node, path, field, "cols");
  if (!cols) return Error(cols.error());
  const cv::FileNode dt = node["dt"];
  const bool plain = ros && (dt.empty() || dt.isNone());
  if (!plain && !dt.isString()) return Error(path + ": " + field + ".dt must be an element type such as d");
  const std::string type = plain ? std::string("d") : dt.string();
  if (type.size() != 1 || std::string_view("ucwsifdh").find(type[0]) == std::string_view::npos)
    return Error(path + ": " + field + " must have one channel of a number type (dt: d), got dt: " + type);
  const int n = *rows * *cols;
  const cv::FileNode data = node["data"];
  if (n == 0 && (data.empty() || data.isNone() || (data.isSeq() && data.size() == 0))) return cv::Mat();
  if (!data.isSeq()) return Error(path + ": " + field + ".data must be a list [ ... ] of " + std::to_string(n) + " numbers");
  if (static_cast<int>(data.size()) != n)
    return Error(path + ": " + field + ".data has " + std::to_string(data.size()) + " values, rows x cols is " +
                 std::to_string(*rows) + "x" + std::to_string(*cols));
  cv::Mat m(*rows, *cols, CV_64F);
  int i = 0;
  for (const cv::FileNode& value : data) {
    const int r = i / *cols, c = i % *cols;
    ++i;
    if (!value.isInt() && !value.isReal())
      return Error(path + ": " + field + ".data value " + std::to_string(i) + " is not a number");
    m.at<double>(r, c) = value.real();
    if (!std::isfinite(m.at<double>(r, c)))
      return Error(path + ": " + field + " has a non-finite value at (" + std::to_string(r) + "," + std::to_string(c) + ")");
  }
  return m;
}

// ROS camera_info YAML (camera_calibration's output): its keys at the start of a line.
bool is_ros_camera_info(std::string_view text) {
  const auto has_key = [&](std::string_view key) {
    for (std::size_t at = text.find(key); at != std::string_view::npos; at = text.find(key, at + 1))
      if (at == 0 || text[at - 1] == '\n') return true;
    return false;
  };
  return has_key("camera_matrix:") && has_key("distortion_model:");
}

// The lens model the file names (ROS's distortion_model, or cv::fisheye's fisheye_model), and
// the ROS name, which also fixes the number of coefficients. A model this reader does not know
// is an error: read as another, it would project pixels off without a word.
struct DeclaredLens {
  LensModel model = LensModel::Pinhole;
  std::string ros_name;  // empty in an OpenCV file
};
std::expected<DeclaredLens, std::string> read_lens(const cv::FileStorage& fs, const std::string& path) {
  const cv::FileNode model = fs["distortion_model"];  // ROS camera_info
  if (!model.empty() && !model.isNone()) {
    const std::string name = model.isString() ? model.string() : std::string("(not a name)");
    if (name == "plumb_bob" || name == "rational_polynomial") return DeclaredLens{LensModel::Pinhole, name};
    if (name == "equidistant") return DeclaredLens{LensModel::Fisheye, name};  // ROS's name for cv::fisheye's model
    return Error(path + ": distortion_model '" + name +
                 "' is not supported: only plumb_bob (k1 k2 p1 p2 k3), rational_polynomial (k1 k2 p1 p2 k3 k4 k5 k6) "
                 "and equidistant (k1..k4)");
  }
  const cv::FileNode fisheye = fs["fisheye_model"];  // what cv::fisheye calibration writes: 1
  if (fisheye.empty() || fisheye.isNone()) return DeclaredLens{};
  if (!fisheye.isInt() || (static_cast<int>(fisheye) != 0 && static_cast<int>(fisheye) != 1))
    return Error(path + ": fisheye_model must be 0 (pinhole) or 1 (cv::fisheye's equidistant model)");
  return DeclaredLens{static_cast<int>(fisheye) == 1 ? LensModel::Fisheye : LensModel::Pinhole, {}};
}

std::expected<Camera, std::string> load_from(const cv::FileStorage& fs, const std::string& path, bool ros) {
  auto lens = read_lens(fs, path);
  if (!lens) return Error(lens.error());
  auto width = read_size(fs, path, "image_width");
  if (!width) return Error(width.error());
  auto height = read_size(fs, path, "image_height");
  if (!height) return Error(height.error());

  auto k = read_matrix(fs, path, "camera_matrix", ros);
  if (!k) return Error(k.error());
  if (k->rows != 3 || k->cols != 3) return Error(path + ": camera_matrix must be 3x3, got " + shape(*k));
  const cv::Mat& K = *k;
  Intrinsics in{K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2)};
  if (!(in.fx_px > 0)) return Error(path + ": fx must be positive");
  if (!(in.fy_px > 0)) return Error(path + ": fy must be positive");
  // The model has no skew and a normalised last row: anything else is a different camera model.
  if (std::abs(K.at<double>(0, 1)) > 1e-9 * in.fx_px)
    return Error(path + ": camera_matrix has skew (element 0,1 = " + std::to_string(K.at<double>(0, 1)) + "), which is not modelled");
  if (K.at<double>(1, 0) != 0 || K.at<double>(2, 0) != 0 || K.at<double>(2, 1) != 0 || K.at<double>(2, 2) != 1)
    return Error(path + ": camera_matrix must have the form [fx 0 cx; 0 fy cy; 0 0 1]");

  auto d = read_matrix(fs, path, "distortion_coefficients", ros);
  if (!d) return Error(d.error());
  Distortion dist{};
  if (!d->empty()) {
    if (d->rows != 1 && d->cols != 1)
      return Error(path + ": distortion_coefficients must be a row or column vector, got " + shape(*d));
    const int n = static_cast<int>(d->total());
    if (lens->model == LensModel::Fisheye && n != 4)
      return Error(path + ": a fisheye calibration (fisheye_model: 1, distortion_model: equidistant) must have 4 "
                          "distortion_coefficients (k1..k4), got " + std::to_string(n));
    if (lens->ros_name == "plumb_bob" && n != 4 && n != 5)
      return Error(path + ": distortion_model plumb_bob has 5 distortion_coefficients (k1 k2 p1 p2 k3), got " +
                   std::to_string(n) + (n == 8 ? " (8 is rational_polynomial)" : ""));
    if (lens->ros_name == "rational_polynomial" && n != 8)
      return Error(path + ": distortion_model rational_polynomial has 8 distortion_coefficients (k1 k2 p1 p2 k3 k4 k5 "
                          "k6), got " + std::to_string(n));
    if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
      return Error(path + ": distortion_coefficients must have 0, 4, 5, 8, 12 or 14 values (OpenCV's models), got " +
                   std::to_string(n));
    for (int i = 0; i < n; ++i) dist[static_cast<std::size_t>(i)] = d->at<double>(i);
  } else if (lens->ros_name == "rational_polynomial") {
    return Error(path + ": distortion_model rational_polynomial has 8 distortion_coefficients (k1 k2 p1 p2 k3 k4 k5 "
                        "k6), got none");
  }
  return Camera(*width, *height, in, dist, lens->model);
}

// OpenCV's tilted-sensor projection (computeTiltProjectionMatrix in calib3d's
// distortion_model.hpp): the sensor rotated by taux about x, then tauy about y, and the image
// projected back along the optical axis onto the tilted plane.
Eigen::Matrix3d tilt_projection(double taux_rad, double tauy_rad) {
  const double cx = std::cos(taux_rad), sx = std::sin(taux_rad), cy = std::cos(tauy_rad), sy = std::sin(tauy_rad);
  Eigen::Matrix3d rot_x, rot_y;
  rot_x << 1, 0, 0, 0, cx, sx, 0, -sx, cx;
  rot_y << cy, 0, -sy, 0, 1, 0, sy, 0, cy;
  const Eigen::Matrix3d rot_xy = rot_y * rot_x;
  Eigen::Matrix3d proj_z;
  proj_z << rot_xy(2, 2), 0, -rot_xy(0, 2), 0, rot_xy(2, 2), -rot_xy(1, 2), 0, 0, 1;
  return proj_z * rot_xy;
}

}  // namespace

Camera::Camera(int width_px, int height_px, const Intrinsics& k, const Distortion& distortion, LensModel lens)
    : width_px_(width_px), height_px_(height_px), k_(k), dist_(distortion), lens_(lens) {
  if (width_px <= 0 || height_px <= 0) throw std::invalid_argument("Camera: image size must be positive");
  if (!(k.fx_px > 0) || !(k.fy_px > 0) || !std::isfinite(k.fx_px) || !std::isfinite(k.fy_px))
    throw std::invalid_argument("Camera: focal lengths must be positive and finite");
  if (!std::isfinite(k.cx_px) || !std::isfinite(k.cy_px)) throw std::invalid_argument("Camera: principal point must be finite");
  for (double c : dist_)
    if (!std::isfinite(c)) throw std::invalid_argument("Camera: distortion coefficients must be finite");
  const auto nonzero_from = [&](std::size_t first) {
    return std::any_of(dist_.begin() + static_cast<std::ptrdiff_t>(first), dist_.end(), [](double c) { return c != 0; });
  };
  if (lens_ == LensModel::Fisheye && nonzero_from(4))
    throw std::invalid_argument("Camera: the fisheye model has four distortion coefficients; the others must be 0");
  // A fisheye lens bends rays even with k1..k4 zero (theta, not tan theta, is proportional to
  // the distance from the principal point).
  has_distortion_ = lens_ == LensModel::Fisheye || nonzero_from(0);
  if (lens_ == LensModel::Fisheye) path_ = Path::Fisheye;
  else if (nonzero_from(5)) path_ = Path::Full;
  else if (has_distortion_) path_ = Path::Brown;
  tilted_ = dist_[12] != 0 || dist_[13] != 0;
  if (tilted_) tilt_ = tilt_projection(dist_[12], dist_[13]);
}

std::expected<Camera, std::string> Camera::load(const std::string& yaml_path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(yaml_path, ec)) return Error(yaml_path + ": cannot open (no such file)");
  const auto size = std::filesystem::file_size(yaml_path, ec);
  if (ec) return Error(yaml_path + ": cannot open (" + ec.message() + ")");
  if (size > kCameraYamlMaxBytes)
    return Error(yaml_path + ": " + std::to_string(size) + " bytes is larger than any camera calibration (1 MiB at most)");
  std::ifstream in(yaml_path, std::ios::binary);
  if (!in) return Error(yaml_path + ": cannot open");
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.empty()) return Error(yaml_path + ": empty file (expected OpenCV FileStorage YAML)");
  if (auto ok = precheck_camera_yaml(text); !ok) return Error(yaml_path + ": not a camera YAML: " + ok.error());
  // OpenCV's YAML reader insists on the directive line. A ROS camera_info file is plain YAML
  // without it and gets one; for anything else, saying so beats OpenCV's "Input file is invalid".
  const bool ros = !text.starts_with("%YAML") && is_ros_camera_info(text);
  if (ros) text.insert(0, "%YAML:1.0\n---\n");
  const std::string hint = text.starts_with("%YAML") ? "" : "; it must start with %YAML:1.0";
  try {
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) return Error(yaml_path + ": cannot open as OpenCV FileStorage YAML" + hint);
    if (!fs.root().isMap()) return Error(yaml_path + ": not an OpenCV FileStorage YAML mapping");
    return load_from(fs, yaml_path, ros);
  } catch (const cv::Exception& e) {
    // OpenCV's parser throws on text that is not YAML.
    return Error(yaml_path + ": not OpenCV FileStorage YAML (" + opencv_reason(e) + hint + ")");
  } catch (const std::exception& e) {
    // OpenCV's parser also lets standard exceptions out (std::length_error, std::bad_alloc).
    return Error(yaml_path + ": not OpenCV FileStorage YAML (the parser failed: " + e.what() + hint + ")");
  }
}

std::expected<void, std::string> Camera::save(const std::string& yaml_path) const {
  // Checked here so that the message is ours (OpenCV would also log its own).
  std::error_code ec;
  const std::filesystem::path parent = std::filesystem::path(yaml_path).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent, ec))
    return Error(yaml_path + ": cannot open for writing (no directory " + parent.string() + ")");
  try {
    cv::FileStorage fs(yaml_path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
    if (!fs.isOpened()) return Error(yaml_path + ": cannot open for writing");
    fs << "image_width" << width_px_ << "image_height" << height_px_;
    const cv::Mat K = (cv::Mat_<double>(3, 3) << k_.fx_px, 0, k_.cx_px, 0, k_.fy_px, k_.cy_px, 0, 0, 1);
    // OpenCV's distCoeffs lengths: the shortest that keeps every non-zero coefficient.
    int n = 4;
    if (lens_ == LensModel::Pinhole) {
      const auto last = std::find_if(dist_.rbegin(), dist_.rend(), [](double c) { return c != 0; });
      const int used = static_cast<int>(dist_.rend() - last);
      n = used <= 5 ? 5 : used <= 8 ? 8 : used <= 12 ? 12 : 14;
    }
    cv::Mat d(1, n, CV_64F);
    for (int i = 0; i < n; ++i) d.at<double>(i) = dist_[static_cast<std::size_t>(i)];
    if (lens_ == LensModel::Fisheye) fs << "fisheye_model" << 1;
    fs << "camera_matrix" << K << "distortion_coefficients" << d;
    fs.release();
  } catch (const cv::Exception& e) {
    return Error(yaml_path + ": cannot write (" + e.err + ")");
  }
  return {};
}

Eigen::Matrix3d Camera::K() const {
  Eigen::Matrix3d K;
  K << k_.fx_px, 0, k_.cx_px, 0, k_.fy_px, k_.cy_px, 0, 0, 1;
  return K;
}

namespace {

// The fisheye model as a radial scale: x_d = s(r) x with r = |x| and s(r) = theta_d(atan r) / r,
// and ds/dr / r for the Jacobian. Near the axis the series (s = 1 + (k1 - 1/3) r^2 + ...)
// replaces the 0/0.
struct FisheyeScale {
  double s, ds_dr_over_r;
};
FisheyeScale fisheye_scale(const Distortion& d, double r2) {
  const double k1 = d[0], k2 = d[1], k3 = d[2], k4 = d[3];
  if (r2 < 1e-16) return {1.0, 2 * (k1 - 1.0 / 3.0)};
  const double r = std::sqrt(r2), theta = std::atan(r), t2 = theta * theta;
  const double theta_d = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))));
  const double dtheta_d = 1 + t2 * (3 * k1 + t2 * (5 * k2 + t2 * (7 * k3 + t2 * 9 * k4)));
  const double dtheta_dr = 1 / (1 + r2);
  return {theta_d / r, (dtheta_d * dtheta_dr * r - theta_d) / (r2 * r)};
}


// OpenCV's full model before the tilt (cvProjectPoints2Internal's xd0, yd0), with its
// derivative when asked for: radial (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 +
// k6 r^6), tangential p1 p2, thin prism s1..s4.
Eigen::Vector2d rational_distort(const Distortion& d, double x, double y, Eigen::Matrix2d* jacobian) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d[4], k4 = d[5], k5 = d[6], k6 = d[7];
  const double s1 = d[8], s2 = d[9], s3 = d[10], s4 = d[11];
  const double r2 = x * x + y * y;
  const double num = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double inv_den = 1 / (1 + r2 * (k4 + r2 * (k5 + r2 * k6)));
  const double radial = num * inv_den;
  const Eigen::Vector2d xd(x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x) + r2 * (s1 + r2 * s2),
                           y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y + r2 * (s3 + r2 * s4));
  if (jacobian) {
    const double dnum = k1 + r2 * (2 * k2 + 3 * k3 * r2), dden = k4 + r2 * (2 * k5 + 3 * k6 * r2);
    const double dradial_dr2 = (dnum - radial * dden) * inv_den;
    const double dradial_dx = 2 * x * dradial_dr2, dradial_dy = 2 * y * dradial_dr2;
    const double prism_x = 2 * (s1 + 2 * s2 * r2), prism_y = 2 * (s3 + 2 * s4 * r2);  // d/dr2 times 2
    Eigen::Matrix2d& J = *jacobian;
    J(0, 0) = radial + x * dradial_dx + 2 * p1 * y + 6 * p2 * x + prism_x * x;
    J(0, 1) = x * dradial_dy + 2 * p1 * x + 2 * p2 * y + prism_x * y;
    J(1, 0) = y * dradial_dx + 2 * p1 * x + 2 * p2 * y + prism_y * x;
    J(1, 1) = radial + y * dradial_dy + 6 * p1 * y + 2 * p2 * x + prism_y * y;
  }
  return xd;
}

// The tilt as cv::projectPoints applies it: v = T (xd, 1), then v.xy / v.z (v.z = 0 divides by 1).
Eigen::Vector2d apply_tilt(const Eigen::Matrix3d& T, const Eigen::Vector2d& xd, Eigen::Matrix2d* jacobian) {
  const Eigen::Vector3d v = T * Eigen::Vector3d(xd.x(), xd.y(), 1.0);
  const double inv = v.z() != 0 ? 1 / v.z() : 1;
  if (jacobian) {
    // d(v.xy / v.z) / d(xd) = (T.xy - (v.xy / v.z) T.z) / v.z on the first two columns.
    const Eigen::Vector2d q = v.head<2>() * inv;
    Eigen::Matrix2d D = T.topLeftCorner<2, 2>() - q * T.block<1, 2>(2, 0);
    *jacobian = (D * inv) * *jacobian;
  }
  return v.head<2>() * inv;
}

}  // namespace

Eigen::Vector2d Camera::normalized_to_pixel(const Eigen::Vector2d& xn) const {
  const double x = xn.x(), y = xn.y();
  switch (path_) {
    case Path::Ideal: return {k_.fx_px * x + k_.cx_px, k_.fy_px * y + k_.cy_px};
    case Path::Fisheye: {
      const double s = fisheye_scale(dist_, x * x + y * y).s;
      return {k_.fx_px * s * x + k_.cx_px, k_.fy_px * s * y + k_.cy_px};
    }
    case Path::Full: {
      Eigen::Vector2d xd = rational_distort(dist_, x, y, nullptr);
      if (tilted_) xd = apply_tilt(tilt_, xd, nullptr);
      return {k_.fx_px * xd.x() + k_.cx_px, k_.fy_px * xd.y() + k_.cy_px};
    }
    case Path::Brown: break;
  }
  const double k1 = dist_[0], k2 = dist_[1], p1 = dist_[2], p2 = dist_[3], k3 = dist_[4];
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {k_.fx_px * xd + k_.cx_px, k_.fy_px * yd + k_.cy_px};
}

Eigen::Matrix2d Camera::normalized_to_pixel_jacobian(const Eigen::Vector2d& xn) const {
  Eigen::Matrix2d J = Eigen::Matrix2d::Identity();
  switch (path_) {
    case Path::Ideal: break;
    case Path::Fisheye: {
      const FisheyeScale f = fisheye_scale(dist_, xn.squaredNorm());
      J = f.s * Eigen::Matrix2d::Identity() + f.ds_dr_over_r * xn * xn.transpose();
      break;
    }
    case Path::Full: {
      const Eigen::Vector2d xd = rational_distort(dist_, xn.x(), xn.y(), &J);
      if (tilted_) apply_tilt(tilt_, xd, &J);
      break;
    }
    case Path::Brown: {
      const double x = xn.x(), y = xn.y();
      const double k1 = dist_[0], k2 = dist_[1], p1 = dist_[2], p2 = dist_[3], k3 = dist_[4];
      const double r2 = x * x + y * y;
      const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
      const double dradial_dr2 = k1 + r2 * (2 * k2 + 3 * k3 * r2);
      const double dradial_dx = 2 * x * dradial_dr2, dradial_dy = 2 * y * dradial_dr2;
      J(0, 0) = radial + x * dradial_dx + 2 * p1 * y + 6 * p2 * x;
      J(0, 1) = x * dradial_dy + 2 * p1 * x + 2 * p2 * y;
      J(1, 0) = y * dradial_dx + 2 * p1 * x + 2 * p2 * y;
      J(1, 1) = radial + y * dradial_dy + 6 * p1 * y + 2 * p2 * x;
      break;
    }
  }
  J.row(0) *= k_.fx_px;
  J.row(1) *= k_.fy_px;
  return J;
}

Eigen::Vector2d Camera::pixel_to_normalized(const Eigen::Vector2d& px) const {
  // Distorted normalised coordinates.
  const Eigen::Vector2d xd((px.x() - k_.cx_px) / k_.fx_px, (px.y() - k_.cy_px) / k_.fy_px);
  if (!has_distortion_ || !xd.allFinite()) return xd;
  // Damped Newton on distort(x) = xd, starting at xd. cv::undistortPoints' fixed-point
  // iteration converges slowly (or not at all) under strong distortion; Newton with a
  // residual-decrease test converges quadratically inside the image and, where the model
  // folds over (far outside the image, no preimage), stops at the closest point it reached.
  const Eigen::Vector2d f(k_.fx_px, k_.fy_px);
  auto residual = [&](const Eigen::Vector2d& x) -> Eigen::Vector2d {
    return (normalized_to_pixel(x) - px).cwiseQuotient(f);
  };
  Eigen::Vector2d x = xd;
  Eigen::Vector2d r = residual(x);
  double err = r.squaredNorm();
  constexpr int kMaxIterations = 50;
  constexpr double kTolerance = 1e-12;  // in normalised units
  for (int it = 0; it < kMaxIterations && std::sqrt(err) > kTolerance; ++it) {
    Eigen::Matrix2d J = normalized_to_pixel_jacobian(x);
    J.row(0) /= k_.fx_px;
    J.row(1) /= k_.fy_px;
    Eigen::Vector2d step;
    const double det = J.determinant();
    if (std::abs(det) > 1e-12) {
      step = -J.inverse() * r;
    } else {
      step = -J.transpose() * r;  // gradient direction at a fold of the model
    }
    if (!step.allFinite()) break;
    bool improved = false;
    for (int halvings = 0; halvings < 40; ++halvings) {
      const Eigen::Vector2d candidate = x + step;
      const Eigen::Vector2d rc = residual(candidate);
      const double ec = rc.squaredNorm();
      if (std::isfinite(ec) && ec < err) {
        x = candidate;
        r = rc;
        err = ec;
        improved = true;
        break;
      }
      step *= 0.5;
    }
    if (!improved) break;  // a local minimum of the residual: no better preimage nearby
  }
  return x;
}

Eigen::Vector2d Camera::project(const Eigen::Vector3d& p_cam) const {
  if (!(p_cam.z() > 0)) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  return normalized_to_pixel(Eigen::Vector2d(p_cam.x() / p_cam.z(), p_cam.y() / p_cam.z()));
}

Eigen::Vector3d Camera::unproject(const Eigen::Vector2d& px) const {
  const Eigen::Vector2d xn = pixel_to_normalized(px);
  return {xn.x(), xn.y(), 1.0};
}

bool Camera::in_image(const Eigen::Vector2d& px, double margin_px) const {
  // Pixel centres are at integer coordinates (OpenCV): the image spans [0, width-1] x [0, height-1].
  return px.x() >= margin_px && px.y() >= margin_px && px.x() <= width_px_ - 1 - margin_px &&
         px.y() <= height_px_ - 1 - margin_px;
}

}  // namespace epichead::vision
