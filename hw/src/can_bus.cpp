#include "epichead/hw/can_bus.h"

namespace epichead::hw {

std::string_view to_string(CanBusState state) {
  switch (state) {
    case CanBusState::ErrorActive: return "error-active";
    case CanBusState::ErrorWarning: return "error-warning";
    case CanBusState::ErrorPassive: return "error-passive";
    case CanBusState::BusOff: return "bus-off";
  }
  return "unknown";
}

}  // namespace epichead::hw
