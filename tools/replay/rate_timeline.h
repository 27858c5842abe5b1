#pragma once
// Frames per channel (message type, "other") and bus time per time bin, for the rate and
// bus-load plots. Bins start at 0.1 s and double in width (merging pairs) whenever there would
// be more than kMaxBins, so memory stays bounded however long the log.
#include <cstdint>
#include <vector>

namespace epichead::tools::replay {

class RateTimeline {
 public:
  static constexpr std::size_t kMaxBins = 1000;
  explicit RateTimeline(int channels) : channels_(channels) {}

  void add(double t_s, int channel, double bus_s);

  int channels() const { return channels_; }
  double start_s() const { return start_s_; }
  double bin_s() const { return bin_s_; }
  std::size_t bins() const { return bus_.size(); }
  double count(std::size_t bin, int channel) const { return counts_[bin * channels_ + channel]; }
  double bus_s(std::size_t bin) const { return bus_[bin]; }

 private:
  int channels_;
  bool started_ = false;
  double start_s_ = 0, bin_s_ = 0.1;
  std::vector<double> counts_;  // bins x channels
  std::vector<double> bus_;
};

}  // namespace epichead::tools::replay
