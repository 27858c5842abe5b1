#include "epichead/vision/offline/pose_covariance_csv.h"

#include <Eigen/Eigenvalues>

#include "csv_rows.h"

namespace epichead::vision {
namespace {

using Error = std::unexpected<std::string>;

constexpr const char* kAxes[6] = {"tx", "ty", "tz", "rx", "ry", "rz"};

std::vector<std::string> make_columns() {
  std::vector<std::string> c{"frame", "t_s"};
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) c.push_back(std::string("c_") + kAxes[i] + "_" + kAxes[j]);
  return c;
}

}  // namespace

const std::vector<std::string>& pose_covariance_columns() {
  static const std::vector<std::string> columns = make_columns();
  return columns;
}

std::expected<std::vector<StampedCovariance>, std::string> read_pose_covariance_csv(const std::string& path) {
  auto table = csv::read(path);
  if (!table) return Error(table.error());
  const std::vector<std::string>& names = pose_covariance_columns();
  const std::vector<std::string_view> columns(names.begin(), names.end());
  if (auto ok = csv::check_header(*table, columns); !ok) return Error(ok.error());
  std::vector<StampedCovariance> out;
  out.reserve(table->rows.size());
  for (const csv::Row& row : table->rows) {
    const std::string at = csv::where(*table, row);
    if (row.fields.size() != columns.size())
      return Error(at + "expected " + std::to_string(columns.size()) + " columns, got " + std::to_string(row.fields.size()));
    StampedCovariance c;
    const auto frame = csv::parse_int(row.fields[0]);
    if (!frame || *frame < 0) return Error(at + "frame is not a whole number >= 0 ('" + row.fields[0] + "')");
    if (!out.empty() && *frame <= out.back().frame)
      return Error(at + "frame " + std::to_string(*frame) + " after frame " + std::to_string(out.back().frame) +
                   " (frames must increase)");
    c.frame = *frame;
    const auto t = csv::parse_finite(row.fields[1]);
    if (!t) return Error(at + csv::number_problem("t_s", row.fields[1]));
    c.t_s = *t;
    std::size_t field = 2;
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j, ++field) {
        const auto v = csv::parse_finite(row.fields[field]);
        if (!v) return Error(at + csv::number_problem(columns[field], row.fields[field]));
        c.covariance(i, j) = c.covariance(j, i) = *v;
      }
    // A covariance with a clearly negative variance along some direction is not one.
    const double scale = c.covariance.cwiseAbs().maxCoeff();
    const double min_ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(c.covariance, Eigen::EigenvaluesOnly)
                              .eigenvalues()
                              .minCoeff();
    if (!(min_ev >= -1e-9 * scale)) return Error(at + "the covariance is not positive semi-definite");
    out.push_back(c);
  }
  return out;
}

std::expected<void, std::string> write_pose_covariance_csv(const std::string& path,
                                                           const std::vector<StampedCovariance>& rows) {
  std::string text;
  const std::vector<std::string>& columns = pose_covariance_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) text += (i ? "," : "") + columns[i];
  text += '\n';
  for (const StampedCovariance& r : rows) {
    text += std::to_string(r.frame);
    text += ',';
    csv::append_exact(text, r.t_s);
    for (int i = 0; i < 6; ++i)
      for (int j = i; j < 6; ++j) {
        text += ',';
        // Exact digits: a nearly singular covariance must read back as the same, still
        // positive semi-definite matrix.
        csv::append_exact(text, 0.5 * (r.covariance(i, j) + r.covariance(j, i)));
      }
    text += '\n';
  }
  return csv::write_file(path, text);
}

}  // namespace epichead::vision
