#include "epichead/firmware_iface/time_sync.h"

#include "frame_codec.h"

namespace epichead::firmware_iface {

using detail::Packer;
using detail::raw_of;

namespace {
constexpr int kSequence = 0, kStamp = 1;
constexpr std::uint64_t kReservedByteMask = 0xFF00;

std::optional<WireError> check_reserved(const CanFrame& f, std::uint64_t word) {
  if (word & kReservedByteMask) return WireError{WireErrorKind::OutOfRange, f.id, 1, "reserved", f.data[1]};
  return std::nullopt;
}
}  // namespace

std::expected<EncodedFrame, WireError> encode(const TimeSyncRequest& m) {
  Packer p(kIdTimeSyncRequest, MessageType::TimeSyncRequest);
  p.raw(kSequence, m.sequence);
  p.raw(kStamp, m.controller_stamp_us & kTimeSyncStampMask);
  return p.finish();
}

std::expected<EncodedFrame, WireError> encode(const TimeSyncReply& m) {
  if (m.node < 1 || m.node > kMaxNode)
    return std::unexpected(WireError{WireErrorKind::OutOfRange, kIdTimeSyncReplyBase, -1, "node", m.node});
  Packer p(message_can_id(MessageType::TimeSyncReply, m.node), MessageType::TimeSyncReply);
  p.raw(kSequence, m.sequence);
  p.raw(kStamp, m.device_stamp_us & kTimeSyncStampMask);
  return p.finish();
}

std::expected<TimeSyncRequest, WireError> decode_time_sync_request(const CanFrame& frame) {
  const auto payload = detail::node_payload_of(frame, MessageType::TimeSyncRequest);
  if (!payload) return std::unexpected(payload.error());
  const std::uint64_t w = payload->word;
  if (auto bad = check_reserved(frame, w)) return std::unexpected(*bad);
  const auto specs = signal_table(MessageType::TimeSyncRequest);
  return TimeSyncRequest{static_cast<std::uint8_t>(raw_of(w, specs[kSequence])),
                         static_cast<std::uint64_t>(raw_of(w, specs[kStamp]))};
}

std::expected<TimeSyncReply, WireError> decode_time_sync_reply(const CanFrame& frame) {
  const auto payload = detail::node_payload_of(frame, MessageType::TimeSyncReply);
  if (!payload) return std::unexpected(payload.error());
  const MessageId* id = &payload->id;
  const std::uint64_t w = payload->word;
  if (auto bad = check_reserved(frame, w)) return std::unexpected(*bad);
  const auto specs = signal_table(MessageType::TimeSyncReply);
  return TimeSyncReply{id->node, static_cast<std::uint8_t>(raw_of(w, specs[kSequence])),
                       static_cast<std::uint64_t>(raw_of(w, specs[kStamp]))};
}

}  // namespace epichead::firmware_iface
