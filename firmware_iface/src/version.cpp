#include "epichead/firmware_iface/version.h"

namespace epichead::firmware_iface {

std::string_view program_version() { return EPICHEAD_VERSION; }

}  // namespace epichead::firmware_iface
