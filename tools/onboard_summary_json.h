#pragma once
// The onboard loop's summary as JSON: the "loop" object of sim-run's summary.json and the whole
// of run's (counts, timings, the deadlines measured on the control thread, the controller's,
// IMU assembly's and predictor's counters).
#include <nlohmann/json.hpp>

#include "epichead/head/onboard_loop.h"

namespace epichead::tools {

nlohmann::json summary_json(const head::OnboardSummary& s);

}  // namespace epichead::tools
