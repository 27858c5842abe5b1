#include <catch2/catch.hpp>

#include <linux/can/error.h>
#include <netinet/in.h>
#include <sys/time.h>

#include <cstring>

#include "epichead/hw/socketcan_frames.h"

using namespace epichead::hw;
using epichead::firmware_iface::CanFlags;

namespace {

canfd_frame kernel_frame(canid_t id, std::initializer_list<std::uint8_t> data) {
  canfd_frame k{};
  k.can_id = id;
  k.len = static_cast<std::uint8_t>(data.size());
  std::copy(data.begin(), data.end(), k.data);
  return k;
}

CanFrame error_frame(std::uint32_t classes, std::uint8_t controller = 0) {
  CanFrame f;
  f.flags = CanFlags::Error;
  f.id = classes;
  f.len = CAN_ERR_DLC;
  f.data[1] = controller;
  return f;
}

}  // namespace

TEST_CASE("a classic kernel frame converts to a standard data frame with its bytes", "[hw][socketcan]") {
  const auto f = from_kernel_frame(kernel_frame(0x123, {1, 2, 3}), CAN_MTU);
  REQUIRE(f);
  CHECK(f->id == 0x123);
  CHECK(f->flags == CanFlags::None);
  CHECK(f->len == 3);
  CHECK(f->data[2] == 3);
}

TEST_CASE("kernel EFF, RTR and ERR flags become Extended, Remote and Error without the flag bits in the id",
          "[hw][socketcan]") {
  const auto ext = from_kernel_frame(kernel_frame(0x1ABCDEF0 | CAN_EFF_FLAG, {}), CAN_MTU);
  REQUIRE(ext);
  CHECK(ext->id == 0x1ABCDEF0);
  CHECK(ext->extended());
  canfd_frame rtr = kernel_frame(0x321 | CAN_RTR_FLAG, {});
  rtr.len = 4;  // the requested length of a remote frame
  const auto remote = from_kernel_frame(rtr, CAN_MTU);
  REQUIRE(remote);
  CHECK(remote->remote());
  CHECK(remote->len == 4);
  const auto err = from_kernel_frame(kernel_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0}), CAN_MTU);
  REQUIRE(err);
  CHECK(err->error());
  CHECK(err->id == CAN_ERR_BUSOFF);
}

TEST_CASE("a CAN FD kernel frame keeps its length and BRS/ESI flags", "[hw][socketcan]") {
  canfd_frame k{};
  k.can_id = 0x55;
  k.len = 12;
  k.flags = CANFD_BRS | CANFD_ESI;
  for (int i = 0; i < 12; ++i) k.data[i] = static_cast<std::uint8_t>(i);
  const auto f = from_kernel_frame(k, CANFD_MTU);
  REQUIRE(f);
  CHECK(f->fd());
  CHECK(has(f->flags, CanFlags::BitRateSwitch));
  CHECK(has(f->flags, CanFlags::ErrorStateIndicator));
  CHECK(f->len == 12);
  CHECK(f->data[11] == 11);
}

TEST_CASE("kernel frames of a wrong size or length are refused with the reason", "[hw][socketcan]") {
  const auto short_read = from_kernel_frame(kernel_frame(0x1, {}), 10);
  REQUIRE_FALSE(short_read);
  CHECK_THAT(short_read.error(), Catch::Contains("10 bytes"));
  canfd_frame long_classic = kernel_frame(0x2, {});
  long_classic.len = 9;
  const auto too_long = from_kernel_frame(long_classic, CAN_MTU);
  REQUIRE_FALSE(too_long);
  CHECK_THAT(too_long.error(), Catch::Contains("0x2") && Catch::Contains("exceeds 8"));
  canfd_frame odd_fd = kernel_frame(0x3, {});
  odd_fd.len = 13;
  CHECK_FALSE(from_kernel_frame(odd_fd, CANFD_MTU));
}

TEST_CASE("frames round-trip through the kernel layout", "[hw][socketcan]") {
  CanFrame f;
  f.id = 0x18FF00AA;
  f.flags = CanFlags::Extended;
  f.len = 8;
  for (int i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(0xA0 + i);
  canfd_frame k;
  const auto size = to_kernel_frame(f, k);
  REQUIRE(size);
  CHECK(*size == CAN_MTU);
  CHECK(k.can_id == (0x18FF00AA | CAN_EFF_FLAG));
  const auto back = from_kernel_frame(k, *size);
  REQUIRE(back);
  CHECK(back->id == f.id);
  CHECK(back->flags == f.flags);
  CHECK(back->data == f.data);

  CanFrame fd;
  fd.id = 0x7FF;
  fd.flags = CanFlags::Fd | CanFlags::BitRateSwitch;
  fd.len = 64;
  fd.data[63] = 0x5A;
  const auto fd_size = to_kernel_frame(fd, k);
  REQUIRE(fd_size);
  CHECK(*fd_size == CANFD_MTU);
  const auto fd_back = from_kernel_frame(k, *fd_size);
  REQUIRE(fd_back);
  CHECK(fd_back->flags == fd.flags);
  CHECK(fd_back->data[63] == 0x5A);
}

TEST_CASE("frames no controller can send are refused before the socket", "[hw][socketcan]") {
  canfd_frame k;
  CanFrame big_id;
  big_id.id = 0x800;  // 12 bits without Extended
  REQUIRE_FALSE(to_kernel_frame(big_id, k));
  CHECK_THAT(to_kernel_frame(big_id, k).error(), Catch::Contains("11 bits"));
  CanFrame long_classic;
  long_classic.len = 9;
  CHECK_FALSE(to_kernel_frame(long_classic, k));
  CanFrame odd_fd;
  odd_fd.flags = CanFlags::Fd;
  odd_fd.len = 10;
  CHECK_FALSE(to_kernel_frame(odd_fd, k));
  CanFrame remote_fd;
  remote_fd.flags = CanFlags::Fd | CanFlags::Remote;
  CHECK_FALSE(to_kernel_frame(remote_fd, k));
  CHECK_FALSE(to_kernel_frame(error_frame(CAN_ERR_BUSOFF), k));
}

TEST_CASE("error frames map to the controller state they report", "[hw][socketcan]") {
  CHECK(classify_error_frame(error_frame(CAN_ERR_BUSOFF)).state == CanBusState::BusOff);
  CHECK(classify_error_frame(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE)).state == CanBusState::ErrorPassive);
  CHECK(classify_error_frame(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING)).state == CanBusState::ErrorWarning);
  CHECK(classify_error_frame(error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE)).state == CanBusState::ErrorActive);
  CHECK(classify_error_frame(error_frame(CAN_ERR_RESTARTED)).state == CanBusState::ErrorActive);
  // Most severe wins when one frame reports several.
  CHECK(classify_error_frame(error_frame(CAN_ERR_BUSOFF | CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING)).state ==
        CanBusState::BusOff);
  // A protocol violation alone says nothing about the state.
  const CanErrorReport prot = classify_error_frame(error_frame(CAN_ERR_PROT | CAN_ERR_BUSERROR));
  CHECK_FALSE(prot.state);
  CHECK(prot.classes == (CAN_ERR_PROT | CAN_ERR_BUSERROR));
  CanFrame counted = error_frame(CAN_ERR_CNT);
  counted.data[6] = 130;
  counted.data[7] = 5;
  const CanErrorReport cnt = classify_error_frame(counted);
  CHECK(cnt.tx_error_count == 130);
  CHECK(cnt.rx_error_count == 5);
  CanFrame data;  // not an error frame: no report
  CHECK(classify_error_frame(data).classes == 0);
}

TEST_CASE("receive metadata gives the kernel time stamp and the drop counter", "[hw][socketcan]") {
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(timeval)) + CMSG_SPACE(sizeof(std::uint32_t))]{};
  msghdr m{};
  m.msg_control = control;
  m.msg_controllen = sizeof control;
  cmsghdr* c = CMSG_FIRSTHDR(&m);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SCM_TIMESTAMP;
  c->cmsg_len = CMSG_LEN(sizeof(timeval));
  const timeval tv{1436509052, 249713};
  std::memcpy(CMSG_DATA(c), &tv, sizeof tv);
  c = CMSG_NXTHDR(&m, c);
  REQUIRE(c != nullptr);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SO_RXQ_OVFL;
  c->cmsg_len = CMSG_LEN(sizeof(std::uint32_t));
  const std::uint32_t dropped = 17;
  std::memcpy(CMSG_DATA(c), &dropped, sizeof dropped);

  const CanReceiveMeta meta = parse_receive_meta(m);
  CHECK(meta.stamp_us == 1436509052249713LL);
  CHECK(meta.dropped_total == 17u);
}

TEST_CASE("truncated or foreign control messages are ignored, not read past", "[hw][socketcan]") {
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(timeval))]{};
  msghdr m{};
  m.msg_control = control;
  m.msg_controllen = sizeof control;
  cmsghdr* c = CMSG_FIRSTHDR(&m);
  c->cmsg_level = SOL_SOCKET;
  c->cmsg_type = SCM_TIMESTAMP;
  c->cmsg_len = CMSG_LEN(2);  // too short for a timeval
  CHECK_FALSE(parse_receive_meta(m).stamp_us);
  c->cmsg_level = IPPROTO_IP;
  c->cmsg_len = CMSG_LEN(sizeof(timeval));
  CHECK_FALSE(parse_receive_meta(m).stamp_us);
  msghdr empty{};
  CHECK_FALSE(parse_receive_meta(empty).dropped_total);
}

TEST_CASE("id filters carry the format in the kernel mask", "[hw][socketcan]") {
  const can_filter any = to_kernel_filter({0x100, 0x700, CanIdFormat::Any});
  CHECK(any.can_id == 0x100);
  CHECK(any.can_mask == 0x700);
  const can_filter standard = to_kernel_filter({0x100, 0x7FF, CanIdFormat::Standard});
  CHECK(standard.can_id == 0x100);
  CHECK(standard.can_mask == (0x7FF | CAN_EFF_FLAG));
  const can_filter extended = to_kernel_filter({0x18FF0000, 0x1FFF0000, CanIdFormat::Extended});
  CHECK(extended.can_id == (0x18FF0000 | CAN_EFF_FLAG));
  CHECK(extended.can_mask == (0x1FFF0000 | CAN_EFF_FLAG));
}
