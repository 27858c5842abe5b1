#pragma once
// Samples kept for a plot in bounded memory: every k-th sample, k doubling (and every other
// kept sample dropped) whenever the buffer is full, so a multi-GB log still plots end to end.
#include <array>
#include <cstddef>
#include <vector>

namespace epichead::tools::replay {

template <std::size_t N>
class BoundedSeries {
 public:
  static constexpr std::size_t kMax = 20000;
  void add(double t_s, const std::array<double, N>& v) {
    if (seen_++ % stride_ != 0) return;
    t_.push_back(t_s);
    v_.push_back(v);
    if (t_.size() >= kMax) {
      std::size_t w = 0;
      for (std::size_t r = 0; r < t_.size(); r += 2, ++w) {
        t_[w] = t_[r];
        v_[w] = v_[r];
      }
      t_.resize(w);
      v_.resize(w);
      stride_ *= 2;
    }
  }
  const std::vector<double>& t() const { return t_; }
  std::vector<double> column(std::size_t i) const {
    std::vector<double> out;
    out.reserve(v_.size());
    for (const auto& v : v_) out.push_back(v[i]);
    return out;
  }
  bool empty() const { return t_.empty(); }

 private:
  std::size_t seen_ = 0, stride_ = 1;
  std::vector<double> t_;
  std::vector<std::array<double, N>> v_;
};

}  // namespace epichead::tools::replay
