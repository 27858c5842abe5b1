#include <catch2/catch.hpp>

#include <linux/can/error.h>

#include <cstring>

#include "epichead/hw/fake_clock.h"
#include "epichead/hw/socketcan_bus.h"
#include "fake_can_kernel.h"

using namespace epichead::hw;
using epichead::firmware_iface::CanFlags;
using epichead::testing::FakeCanKernel;

namespace {

std::unique_ptr<SocketCanBus> open_fake(FakeCanKernel& kernel, SocketCanOptions options = {}) {
  static FakeClock clock;
  auto bus = SocketCanBus::open(options, kernel, clock);
  REQUIRE(bus);
  return std::move(*bus);
}

template <class T>
T option_value(const FakeCanKernel& kernel, int name) {
  T value{};
  const auto& bytes = kernel.options.at(name);
  REQUIRE(bytes.size() >= sizeof value);
  std::memcpy(&value, bytes.data(), sizeof value);
  return value;
}

}  // namespace

TEST_CASE("opening sets up a non-blocking socket with filters, error frames, stamps and drop counts",
          "[hw][socketcan]") {
  FakeCanKernel kernel;
  SocketCanOptions options;
  options.interface = "can1";
  options.filters = {{0x100, 0x700, CanIdFormat::Standard}, {0x18FF0000, 0x1FFF0000, CanIdFormat::Extended}};
  auto bus = open_fake(kernel, options);
  CHECK(kernel.nonblocking);
  CHECK(kernel.bound_ifindex == 7);
  REQUIRE(kernel.options.at(CAN_RAW_FILTER).size() == 2 * sizeof(can_filter));
  const auto first = option_value<can_filter>(kernel, CAN_RAW_FILTER);
  CHECK(first.can_id == 0x100);
  CHECK(option_value<can_err_mask_t>(kernel, CAN_RAW_ERR_FILTER) == CAN_ERR_MASK);
  CHECK(option_value<int>(kernel, SO_TIMESTAMP) == 1);
  CHECK(option_value<int>(kernel, SO_RXQ_OVFL) == 1);
  CHECK(kernel.options.count(CAN_RAW_FD_FRAMES) == 0);
  bus.reset();
  CHECK(kernel.closed == 1);
}

TEST_CASE("the receive queue is sized for stalls: forced when allowed, else the capped plain size",
          "[hw][socketcan]") {
  FakeCanKernel privileged, unprivileged, kernel_default;  // outlive the buses that use them
  auto forced = open_fake(privileged);
  CHECK(option_value<int>(privileged, SO_RCVBUFFORCE) == 1 << 20);
  CHECK(privileged.options.count(SO_RCVBUF) == 0);

  unprivileged.setsockopt_errno[SO_RCVBUFFORCE] = EPERM;
  SocketCanOptions options;
  options.receive_buffer_bytes = 300000;
  auto capped = open_fake(unprivileged, options);
  CHECK(option_value<int>(unprivileged, SO_RCVBUF) == 300000);

  options.receive_buffer_bytes = 0;
  auto untouched = open_fake(kernel_default, options);
  CHECK(kernel_default.options.count(SO_RCVBUFFORCE) == 0);
  CHECK(kernel_default.options.count(SO_RCVBUF) == 0);

  FakeCanKernel refused;
  refused.setsockopt_errno[SO_RCVBUFFORCE] = EPERM;
  refused.setsockopt_errno[SO_RCVBUF] = ENOMEM;
  auto r = SocketCanBus::open({}, refused);
  REQUIRE_FALSE(r);
  CHECK_THAT(r.error(), Catch::Contains("'can0'") && Catch::Contains("receive queue"));
  CHECK(refused.closed == 1);

  options.receive_buffer_bytes = -1;
  FakeCanKernel unused;
  r = SocketCanBus::open(options, unused);
  REQUIRE_FALSE(r);
  CHECK_THAT(r.error(), Catch::Contains("receive_buffer_bytes"));
}

TEST_CASE("each set-up failure names the interface and the step, and closes the socket", "[hw][socketcan]") {
  FakeCanKernel no_can;
  no_can.socket_errno = EAFNOSUPPORT;
  auto r = SocketCanBus::open({}, no_can);
  REQUIRE_FALSE(r);
  CHECK_THAT(r.error(), Catch::Contains("'can0'") && Catch::Contains("CAN_RAW socket") && Catch::Contains("can_raw"));

  FakeCanKernel missing;
  missing.ifindex_errno = ENODEV;
  SocketCanOptions options;
  options.interface = "vcan3";
  r = SocketCanBus::open(options, missing);
  REQUIRE_FALSE(r);
  CHECK_THAT(r.error(), Catch::Contains("'vcan3'") && Catch::Contains("no such"));
  CHECK(missing.closed == 1);

  FakeCanKernel no_ovfl;
  no_ovfl.setsockopt_errno[SO_RXQ_OVFL] = ENOPROTOOPT;
  r = SocketCanBus::open({}, no_ovfl);
  REQUIRE_FALSE(r);
  CHECK_THAT(r.error(), Catch::Contains("SO_RXQ_OVFL"));
  CHECK(no_ovfl.closed == 1);

  FakeCanKernel bind_fails;
  bind_fails.bind_errno = ENETDOWN;
  CHECK_FALSE(SocketCanBus::open({}, bind_fails));
  CHECK(bind_fails.closed == 1);

  options.interface = "a_name_longer_than_ifnamsiz";
  FakeCanKernel unused;
  r = SocketCanBus::open(options, unused);
  REQUIRE_FALSE(r);
  CHECK_THAT(r.error(), Catch::Contains("1 to 15 characters"));
}

TEST_CASE("received frames carry the kernel time stamp and are counted", "[hw][socketcan]") {
  FakeCanKernel kernel;
  auto bus = open_fake(kernel);
  kernel.push(0x123, {0xDE, 0xAD}, timeval{1436509052, 249713});
  StampedCanFrame got;
  REQUIRE(bus->receive(got, 0.1) == CanReceive::Frame);
  CHECK(got.stamp_us == 1436509052249713LL);
  CHECK(got.frame.id == 0x123);
  CHECK(got.frame.len == 2);
  CHECK(got.frame.data[1] == 0xAD);
  CHECK(bus->stats().rx_frames == 1);
  CHECK(bus->receive(got, 0.1) == CanReceive::Timeout);
}

TEST_CASE("a bus-off error frame is delivered, counted and sets the state until the controller restarts",
          "[hw][socketcan]") {
  FakeCanKernel kernel;
  auto bus = open_fake(kernel);
  kernel.push(CAN_ERR_FLAG | CAN_ERR_CRTL, {0, CAN_ERR_CRTL_TX_PASSIVE, 0, 0, 0, 0, 0, 0});
  kernel.push(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0});
  kernel.push(CAN_ERR_FLAG | CAN_ERR_RESTARTED, {0, 0, 0, 0, 0, 0, 0, 0});
  StampedCanFrame got;
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  CHECK(bus->stats().state == CanBusState::ErrorPassive);
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  CHECK(got.frame.error());
  CHECK(bus->stats().state == CanBusState::BusOff);
  CHECK(bus->stats().bus_off_events == 1);
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  CHECK(bus->stats().state == CanBusState::ErrorActive);
  CHECK(bus->stats().rx_error_frames == 3);
  CHECK(bus->stats().rx_frames == 0);
}

TEST_CASE("the kernel's drop counter adds up across frames, also when it wraps", "[hw][socketcan]") {
  FakeCanKernel kernel;
  auto bus = open_fake(kernel);
  kernel.push(0x1, {}, std::nullopt, 3);
  kernel.push(0x2, {}, std::nullopt, 10);
  StampedCanFrame got;
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  CHECK(bus->stats().rx_dropped == 10);
  kernel.push(0x3, {}, std::nullopt, 0xFFFFFFFFu);
  kernel.push(0x4, {}, std::nullopt, 4);  // wrapped: 5 more since the last total
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  CHECK(bus->stats().rx_dropped == 10 + (0xFFFFFFFFull - 10) + 5);
}

TEST_CASE("a malformed read is counted and skipped, the next frame still arrives", "[hw][socketcan]") {
  FakeCanKernel kernel;
  auto bus = open_fake(kernel);
  kernel.push(0x1, {});
  kernel.queue.back().nbytes = 5;
  kernel.push(0x2, {7});
  StampedCanFrame got;
  REQUIRE(bus->receive(got, 0) == CanReceive::Frame);
  CHECK(got.frame.id == 0x2);
  CHECK(bus->stats().rx_malformed == 1);
}

TEST_CASE("a failing socket returns Error with the reason, EAGAIN is a timeout", "[hw][socketcan]") {
  FakeCanKernel kernel;
  auto bus = open_fake(kernel);
  StampedCanFrame got;
  CHECK(bus->receive(got, 0) == CanReceive::Timeout);
  CHECK(bus->last_error().empty());
  epichead::testing::KernelDelivery down;
  down.error = ENETDOWN;
  kernel.queue.push_back(down);
  REQUIRE(bus->receive(got, 0) == CanReceive::Error);
  CHECK_THAT(std::string(bus->last_error()), Catch::Contains("can0") && Catch::Contains("interface down"));
}

TEST_CASE("a socket that polls as failed but has nothing to read times out instead of hanging",
          "[hw][socketcan]") {
  FakeCanKernel kernel;
  auto bus = SocketCanBus::open({}, kernel);  // the real monotonic clock bounds the wait
  REQUIRE(bus);
  kernel.stuck_pollerr = true;
  StampedCanFrame got;
  CHECK((*bus)->receive(got, 0.02) == CanReceive::Timeout);
  CHECK(kernel.polls >= 1);
}

TEST_CASE("sends write the kernel layout, refusals are counted with the reason", "[hw][socketcan]") {
  FakeCanKernel kernel;
  auto bus = open_fake(kernel);
  CanFrame f;
  f.id = 0x7E0;
  f.len = 2;
  f.data[0] = 0x11;
  REQUIRE(bus->send(f));
  REQUIRE(kernel.written.size() == 1);
  REQUIRE(kernel.written[0].size == CAN_MTU);
  CHECK(kernel.written[0].frame.can_id == 0x7E0);
  CHECK(kernel.written[0].frame.len == 2);
  CHECK(kernel.written[0].frame.data[0] == 0x11);
  CHECK(bus->stats().tx_frames == 1);

  kernel.write_errno = ENOBUFS;
  auto full = bus->send(f);
  REQUIRE_FALSE(full);
  CHECK_THAT(full.error(), Catch::Contains("transmit queue full"));
  CanFrame invalid;
  invalid.id = 0x900;
  CHECK_FALSE(bus->send(invalid));
  CHECK(bus->stats().tx_failed == 2);
}

TEST_CASE("on this kernel, opening a CAN interface that is not there fails with its name", "[hw][socketcan]") {
  // Real socket calls: without CAN support the socket fails, with it the interface is missing.
  SocketCanOptions options;
  options.interface = "epichead_nocan";
  const auto bus = SocketCanBus::open(options);
  REQUIRE_FALSE(bus);
  CHECK_THAT(bus.error(), Catch::Contains("'epichead_nocan'"));
  INFO(bus.error());
}
