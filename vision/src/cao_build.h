#pragma once
// Private to the CAO reader: build_model with the source location of every item, so that the
// reader's warnings and errors name "file:line" rather than an index.
#include <expected>
#include <string>
#include <vector>

#include "epichead/vision/cao_model.h"

namespace epichead::vision::detail {

// "file:line" of each face loop, free line, circle and cylinder of a RawModel (same order).
// Items past the end of a list are named by the model name and their index instead.
struct RawSources {
  std::vector<std::string> faces, lines, circles, cylinders;
};

std::expected<CadModel, std::string> build_model_located(const RawModel& raw, const std::string& name,
                                                         const RawSources* where);

}  // namespace epichead::vision::detail
