#include "epichead/fusion/gated_agreement.h"

#include <Eigen/Cholesky>

namespace epichead::fusion {

bool GatedAgreement::add(double t_s, const geometry::Vector6d& innovation, const geometry::Matrix6d& covariance) {
  int agreeing = 1;
  for (std::size_t k = 0; k < gated_.size(); ++k) {
    const Entry& g = gated_[k];
    if (!(t_s - g.t_s <= options_.window_s)) continue;
    const geometry::Vector6d d = innovation - g.innovation;
    const Eigen::LDLT<geometry::Matrix6d> sum(covariance + g.covariance);
    if (sum.info() == Eigen::Success && d.dot(sum.solve(d)) <= options_.chi2) ++agreeing;
  }
  gated_.push_overwrite(Entry{t_s, innovation, covariance});
  return agreeing >= options_.restart_after;
}

}  // namespace epichead::fusion
