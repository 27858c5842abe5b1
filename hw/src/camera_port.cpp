#include "epichead/hw/camera_port.h"

namespace epichead::hw {

std::string_view to_string(CameraState state) {
  switch (state) {
    case CameraState::Stopped: return "stopped";
    case CameraState::Streaming: return "streaming";
    case CameraState::Reconnecting: return "reconnecting";
  }
  return "unknown";
}

}  // namespace epichead::hw
