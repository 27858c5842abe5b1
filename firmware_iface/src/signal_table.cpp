#include "epichead/firmware_iface/signal_table.h"

#include <array>

namespace epichead::firmware_iface {
namespace {

constexpr double kU48Max = 281474976710655.0;  // 2^48 - 1

// Range of a signed field of `bits` bits at `factor`.
constexpr double smin(int bits, double factor) { return -static_cast<double>(1LL << (bits - 1)) * factor; }
constexpr double smax(int bits, double factor) { return static_cast<double>((1LL << (bits - 1)) - 1) * factor; }

constexpr std::array kTimeSyncRequest = {
    SignalSpec{"sequence", 0, 8, false, 1, 0, 0, 255, ""},
    SignalSpec{"controller_stamp", 16, 48, false, 1, 0, 0, kU48Max, "us"},
};
constexpr std::array kTimeSyncReply = {
    SignalSpec{"sequence", 0, 8, false, 1, 0, 0, 255, ""},
    SignalSpec{"device_stamp", 16, 48, false, 1, 0, 0, kU48Max, "us"},
};
// HeadCommand and HeadState share one layout.
constexpr std::array kHeadJoints = {
    SignalSpec{"counter", 0, 4, false, 1, 0, 0, 15, ""},
    SignalSpec{"mode", 4, 4, false, 1, 0, 0, 3, ""},
    SignalSpec{"pan_angle", 8, 16, true, 1e-4, 0, smin(16, 1e-4), smax(16, 1e-4), "rad"},
    SignalSpec{"tilt_angle", 24, 16, true, 1e-4, 0, smin(16, 1e-4), smax(16, 1e-4), "rad"},
    SignalSpec{"pan_rate", 40, 12, true, 0.005, 0, smin(12, 0.005), smax(12, 0.005), "rad/s"},
    SignalSpec{"tilt_rate", 52, 12, true, 0.005, 0, smin(12, 0.005), smax(12, 0.005), "rad/s"},
};
constexpr std::array kImuGyro = {
    SignalSpec{"gyro_x", 0, 16, true, 0.00125, 0, smin(16, 0.00125), smax(16, 0.00125), "rad/s"},
    SignalSpec{"gyro_y", 16, 16, true, 0.00125, 0, smin(16, 0.00125), smax(16, 0.00125), "rad/s"},
    SignalSpec{"gyro_z", 32, 16, true, 0.00125, 0, smin(16, 0.00125), smax(16, 0.00125), "rad/s"},
    SignalSpec{"counter", 48, 4, false, 1, 0, 0, 15, ""},
    SignalSpec{"stamp", 52, 12, false, 16, 0, 0, 65520, "us"},
};
constexpr std::array kImuAccel = {
    SignalSpec{"accel_x", 0, 16, true, 0.005, 0, smin(16, 0.005), smax(16, 0.005), "m/s^2"},
    SignalSpec{"accel_y", 16, 16, true, 0.005, 0, smin(16, 0.005), smax(16, 0.005), "m/s^2"},
    SignalSpec{"accel_z", 32, 16, true, 0.005, 0, smin(16, 0.005), smax(16, 0.005), "m/s^2"},
    SignalSpec{"counter", 48, 4, false, 1, 0, 0, 15, ""},
    SignalSpec{"stamp", 52, 12, false, 16, 0, 0, 65520, "us"},
};
constexpr std::array kHeadStatus = {
    SignalSpec{"pan_current", 0, 16, true, 0.001, 0, smin(16, 0.001), smax(16, 0.001), "A"},
    SignalSpec{"tilt_current", 16, 16, true, 0.001, 0, smin(16, 0.001), smax(16, 0.001), "A"},
    SignalSpec{"faults", 32, 16, false, 1, 0, 0, 511, ""},
    SignalSpec{"counter", 48, 8, false, 1, 0, 0, 255, ""},
    SignalSpec{"temperature", 56, 8, true, 1, 0, -128, 127, "degC"},
};
constexpr std::array kHeartbeat = {
    SignalSpec{"state", 0, 8, false, 1, 0, 0, 3, ""},
    SignalSpec{"protocol_version", 8, 8, false, 1, 0, 0, 255, ""},
    SignalSpec{"firmware_major", 16, 8, false, 1, 0, 0, 255, ""},
    SignalSpec{"firmware_minor", 24, 8, false, 1, 0, 0, 255, ""},
    SignalSpec{"firmware_patch", 32, 8, false, 1, 0, 0, 255, ""},
    SignalSpec{"uptime", 40, 24, false, 1, 0, 0, 16777215, "s"},
};

}  // namespace

std::span<const SignalSpec> signal_table(MessageType type) {
  switch (type) {
    case MessageType::TimeSyncRequest: return kTimeSyncRequest;
    case MessageType::TimeSyncReply: return kTimeSyncReply;
    case MessageType::HeadCommand:
    case MessageType::HeadState: return kHeadJoints;
    case MessageType::ImuGyro: return kImuGyro;
    case MessageType::ImuAccel: return kImuAccel;
    case MessageType::HeadStatus: return kHeadStatus;
    case MessageType::Heartbeat: return kHeartbeat;
  }
  return {};
}

}  // namespace epichead::firmware_iface
