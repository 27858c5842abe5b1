#include <linux/can/error.h>
#include <sys/time.h>

#include <cstdio>
#include <cstring>
#include <ctime>

#include "epichead/hw/socketcan_frames.h"

namespace epichead::hw {
namespace {

using firmware_iface::CanFlags;
using firmware_iface::kCanFdMaxData;
using firmware_iface::kCanMaxData;

bool is_fd_length(unsigned len) {
  return len <= 8 || len == 12 || len == 16 || len == 20 || len == 24 || len == 32 || len == 48 || len == 64;
}

std::string hex_id(std::uint32_t id) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%X", static_cast<unsigned>(id));
  return text;
}

// The most severe state among those an error frame reports (bus-off > passive > warning > active).
std::optional<CanBusState> reported_state(std::uint32_t classes, std::uint8_t controller) {
  if (classes & CAN_ERR_BUSOFF) return CanBusState::BusOff;
  if (classes & CAN_ERR_CRTL) {
    if (controller & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) return CanBusState::ErrorPassive;
    if (controller & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) return CanBusState::ErrorWarning;
    if (controller & CAN_ERR_CRTL_ACTIVE) return CanBusState::ErrorActive;
  }
  if (classes & CAN_ERR_RESTARTED) return CanBusState::ErrorActive;
  return std::nullopt;
}

}  // namespace

std::expected<CanFrame, std::string> from_kernel_frame(const canfd_frame& kernel, std::size_t nbytes) {
  const bool fd = nbytes == CANFD_MTU;
  if (!fd && nbytes != CAN_MTU) {
    return std::unexpected("CAN frame of " + std::to_string(nbytes) + " bytes (expected " +
                           std::to_string(CAN_MTU) + " or " + std::to_string(CANFD_MTU) + ")");
  }
  CanFrame frame;
  const canid_t raw = kernel.can_id;
  if (raw & CAN_ERR_FLAG) {
    frame.flags = CanFlags::Error;
    frame.id = raw & CAN_ERR_MASK;
  } else if (raw & CAN_EFF_FLAG) {
    frame.flags = CanFlags::Extended;
    frame.id = raw & CAN_EFF_MASK;
  } else {
    frame.id = raw & CAN_SFF_MASK;
  }
  if (!fd && (raw & CAN_RTR_FLAG) && !(raw & CAN_ERR_FLAG)) frame.flags = frame.flags | CanFlags::Remote;
  const unsigned max_len = fd ? kCanFdMaxData : kCanMaxData;
  if (kernel.len > max_len || (fd && !is_fd_length(kernel.len))) {
    return std::unexpected("CAN frame " + hex_id(frame.id) + ": length " + std::to_string(kernel.len) +
                           (fd ? " is not a CAN FD length" : " exceeds 8"));
  }
  frame.len = kernel.len;
  if (fd) {
    frame.flags = frame.flags | CanFlags::Fd;
    if (kernel.flags & CANFD_BRS) frame.flags = frame.flags | CanFlags::BitRateSwitch;
    if (kernel.flags & CANFD_ESI) frame.flags = frame.flags | CanFlags::ErrorStateIndicator;
  }
  // A remote frame's len is its requested length; it carries no data.
  if (!frame.remote()) std::memcpy(frame.data.data(), kernel.data, frame.len);
  return frame;
}

std::expected<std::size_t, std::string> to_kernel_frame(const CanFrame& frame, canfd_frame& kernel) {
  if (frame.error()) return std::unexpected("CAN frame " + hex_id(frame.id) + ": error frames cannot be sent");
  const std::uint32_t max_id = frame.extended() ? CAN_EFF_MASK : CAN_SFF_MASK;
  if (frame.id > max_id) {
    return std::unexpected("CAN id " + hex_id(frame.id) + " does not fit " +
                           (frame.extended() ? "29 bits" : "11 bits (set Extended for a 29-bit id)"));
  }
  if (frame.fd() && frame.remote()) return std::unexpected("CAN frame " + hex_id(frame.id) + ": CAN FD has no remote frames");
  if (frame.fd() ? !is_fd_length(frame.len) : frame.len > kCanMaxData) {
    return std::unexpected("CAN frame " + hex_id(frame.id) + ": length " + std::to_string(frame.len) +
                           (frame.fd() ? " is not a CAN FD length" : " exceeds 8"));
  }
  kernel = canfd_frame{};
  kernel.can_id = frame.id | (frame.extended() ? CAN_EFF_FLAG : 0U) | (frame.remote() ? CAN_RTR_FLAG : 0U);
  kernel.len = frame.len;
  if (frame.fd()) {
    if (has(frame.flags, CanFlags::BitRateSwitch)) kernel.flags |= CANFD_BRS;
    if (has(frame.flags, CanFlags::ErrorStateIndicator)) kernel.flags |= CANFD_ESI;
  }
  if (!frame.remote()) std::memcpy(kernel.data, frame.data.data(), frame.len);
  return frame.fd() ? CANFD_MTU : CAN_MTU;
}

CanErrorReport classify_error_frame(const CanFrame& frame) {
  CanErrorReport report;
  if (!frame.error()) return report;
  report.classes = frame.id & CAN_ERR_MASK;
  // The payload bytes beyond len read as zero (CanFrame zero-fills), so a short error frame
  // reports fewer details instead of reading garbage.
  const std::uint8_t controller = frame.len > 1 ? frame.data[1] : 0;
  report.state = reported_state(report.classes, controller);
  if ((report.classes & CAN_ERR_CNT) && frame.len >= 8) {
    report.tx_error_count = frame.data[6];
    report.rx_error_count = frame.data[7];
  }
  return report;
}

CanReceiveMeta parse_receive_meta(const msghdr& message) {
  CanReceiveMeta meta;
  if (message.msg_control == nullptr) return meta;
  // CMSG_NXTHDR takes a non-const msghdr but does not modify it.
  auto& m = const_cast<msghdr&>(message);
  for (cmsghdr* c = CMSG_FIRSTHDR(&m); c != nullptr; c = CMSG_NXTHDR(&m, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    const std::size_t payload = c->cmsg_len >= CMSG_LEN(0) ? c->cmsg_len - CMSG_LEN(0) : 0;
    if (c->cmsg_type == SCM_TIMESTAMP && payload >= sizeof(timeval)) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      meta.stamp_us = static_cast<std::int64_t>(tv.tv_sec) * 1'000'000 + tv.tv_usec;
    } else if (c->cmsg_type == SCM_TIMESTAMPNS && payload >= sizeof(timespec)) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      meta.stamp_us = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + ts.tv_nsec / 1000;
    } else if (c->cmsg_type == SO_RXQ_OVFL && payload >= sizeof(std::uint32_t)) {
      std::uint32_t dropped = 0;
      std::memcpy(&dropped, CMSG_DATA(c), sizeof dropped);
      meta.dropped_total = dropped;
    }
  }
  return meta;
}

can_filter to_kernel_filter(const CanIdFilter& filter) {
  can_filter k{};
  switch (filter.format) {
    case CanIdFormat::Any:
      k.can_id = filter.id & CAN_EFF_MASK;
      k.can_mask = filter.mask & CAN_EFF_MASK;
      break;
    case CanIdFormat::Standard:
      k.can_id = filter.id & CAN_SFF_MASK;
      k.can_mask = (filter.mask & CAN_SFF_MASK) | CAN_EFF_FLAG;
      break;
    case CanIdFormat::Extended:
      k.can_id = (filter.id & CAN_EFF_MASK) | CAN_EFF_FLAG;
      k.can_mask = (filter.mask & CAN_EFF_MASK) | CAN_EFF_FLAG;
      break;
  }
  return k;
}

}  // namespace epichead::hw
