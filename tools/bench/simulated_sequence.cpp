#include "bench/simulated_sequence.h"

#include <filesystem>
#include <stdexcept>

#include <unistd.h>

#include "epichead/sim/scenario.h"
#include "epichead/sim/sequence_writer.h"

namespace epichead::bench {

SimulatedSequence simulate_builtin(const std::string& name, int frames) {
  auto scenario = sim::find_scenario(name);
  if (!scenario) throw std::runtime_error(scenario.error());
  scenario->frames = frames;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("epichead-bench-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  if (auto written = sim::write_sequence(*scenario, dir.string()); !written) throw std::runtime_error(written.error());
  auto seq = vision::Sequence::open(dir.string());
  if (!seq) throw std::runtime_error(seq.error());
  SimulatedSequence out{std::make_unique<vision::Sequence>(std::move(*seq)), {}};
  for (std::size_t i = 0; i < out.seq->frame_count(); ++i) {
    auto frame = out.seq->read_frame(i);
    if (!frame) throw std::runtime_error(frame.error());
    out.frames.push_back(*frame);
  }
  std::filesystem::remove_all(dir);
  return out;
}

}  // namespace epichead::bench
