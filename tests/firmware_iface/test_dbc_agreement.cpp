// The shipped DBC (firmware_iface/epichead.dbc) describes exactly the frames the C++ code
// encodes: every BO_ is a message of the protocol, every message type is in the DBC, and
// every SG_ agrees with signal_table.h in start bit, length, byte order, sign, factor,
// offset, range and unit.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <algorithm>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/signal_table.h"

using namespace epichead::firmware_iface;

namespace {

struct DbcSignal {
  std::string name;
  int start = 0, length = 0;
  bool intel = true, is_signed = false;
  double factor = 0, offset = 0, min = 0, max = 0;
  std::string unit;
};
struct DbcMessage {
  std::uint32_t id = 0;
  std::string name;
  int dlc = 0;
  std::vector<DbcSignal> signals;
};

// A reader for the subset of DBC the file uses (BO_ and SG_ lines, no multiplexing).
std::vector<DbcMessage> read_dbc(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  std::vector<DbcMessage> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("BO_ ", 0) == 0) {
      unsigned long id = 0;
      char name[128] = {};
      int dlc = 0;
      REQUIRE(std::sscanf(line.c_str(), "BO_ %lu %127[^: ] : %d", &id, name, &dlc) == 3);
      out.push_back({static_cast<std::uint32_t>(id), name, dlc, {}});
    } else if (line.rfind(" SG_ ", 0) == 0) {
      INFO(line);
      DbcSignal s;
      char name[128] = {};
      char order = 0, sign = 0;
      REQUIRE(std::sscanf(line.c_str(), " SG_ %127s : %d|%d@%c%c (%lf,%lf) [%lf|%lf]", name, &s.start, &s.length,
                          &order, &sign, &s.factor, &s.offset, &s.min, &s.max) == 9);
      s.name = name;
      s.intel = order == '1';
      s.is_signed = sign == '-';
      const auto q1 = line.find('"');
      const auto q2 = line.find('"', q1 + 1);
      REQUIRE(q2 != std::string::npos);
      s.unit = line.substr(q1 + 1, q2 - q1 - 1);
      REQUIRE_FALSE(out.empty());
      out.back().signals.push_back(s);
    }
  }
  return out;
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b)); }

}  // namespace

TEST_CASE("Every DBC signal agrees with the C++ signal table") {
  const auto messages = read_dbc(std::string(EPICHEAD_TEST_DATA) + "/../../firmware_iface/epichead.dbc");
  REQUIRE(messages.size() >= static_cast<std::size_t>(kMessageTypeCount));
  std::set<MessageType> seen;
  for (const auto& msg : messages) {
    INFO("BO_ " << msg.id << " " << msg.name);
    const auto id = classify_id(msg.id);
    REQUIRE(id.has_value());
    seen.insert(id->type);
    CHECK(msg.name.rfind(std::string(to_string(id->type)), 0) == 0);  // name starts with the type
    CHECK(msg.dlc == kFrameLength);
    const auto table = signal_table(id->type);
    REQUIRE(msg.signals.size() == table.size());
    for (const auto& spec : table) {
      INFO("signal " << spec.name);
      const auto it = std::find_if(msg.signals.begin(), msg.signals.end(),
                                   [&](const DbcSignal& s) { return s.name == spec.name; });
      REQUIRE(it != msg.signals.end());
      CHECK(it->start == spec.start_bit);
      CHECK(it->length == spec.length);
      CHECK(it->intel);
      CHECK(it->is_signed == spec.is_signed);
      CHECK(close(it->factor, spec.factor));
      CHECK(close(it->offset, spec.offset));
      CHECK(close(it->min, spec.min));
      CHECK(close(it->max, spec.max));
      CHECK(it->unit == spec.unit);
    }
  }
  CHECK(seen.size() == static_cast<std::size_t>(kMessageTypeCount));
}

TEST_CASE("Signals of a message do not overlap and fit in 8 bytes") {
  for (int t = 0; t < kMessageTypeCount; ++t) {
    const auto table = signal_table(static_cast<MessageType>(t));
    REQUIRE_FALSE(table.empty());
    std::uint64_t used = 0;
    for (const auto& s : table) {
      INFO(to_string(static_cast<MessageType>(t)) << "." << s.name);
      REQUIRE(s.start_bit + s.length <= 64);
      const std::uint64_t mask = (s.length == 64 ? ~0ULL : ((1ULL << s.length) - 1)) << s.start_bit;
      CHECK((used & mask) == 0);
      used |= mask;
      // The stated physical range is what the raw field can carry.
      const double lo = s.is_signed ? -std::ldexp(1.0, s.length - 1) : 0.0;
      const double hi = s.is_signed ? std::ldexp(1.0, s.length - 1) - 1 : std::ldexp(1.0, s.length) - 1;
      CHECK(s.min >= lo * s.factor + s.offset - 1e-9);
      CHECK(s.max <= hi * s.factor + s.offset + 1e-9);
    }
  }
}
