#include <catch2/catch.hpp>

#include <linux/gpio.h>
#include <unistd.h>

#include "epichead/hw/fake_clock.h"
#include "epichead/hw/gpio_event_fd_reader.h"
#include "epichead/hw/gpiod_edge_input.h"
#include "epichead/hw/gpiod_output.h"

using namespace epichead::hw;

namespace {

// A pipe standing in for a GPIO line's event descriptor: the test writes what the kernel would.
struct EventPipe {
  int fds[2] = {-1, -1};
  EventPipe() { REQUIRE(::pipe(fds) == 0); }
  ~EventPipe() {
    if (fds[0] >= 0) ::close(fds[0]);
    if (fds[1] >= 0) ::close(fds[1]);
  }
  void edge(std::uint64_t timestamp_ns, std::uint32_t id) {
    gpioevent_data e{};
    e.timestamp = timestamp_ns;
    e.id = id;
    REQUIRE(::write(fds[1], &e, sizeof e) == static_cast<ssize_t>(sizeof e));
  }
  void close_writer() {
    ::close(fds[1]);
    fds[1] = -1;
  }
};

}  // namespace

TEST_CASE("edge events from the line's descriptor keep the kernel time stamp (in seconds) and direction", "[hw][gpio]") {
  EventPipe pipe;
  GpioEventFdReader reader(pipe.fds[0], "GPIO test line 3");
  pipe.edge(1'234'567'890'123ull, GPIOEVENT_EVENT_RISING_EDGE);
  pipe.edge(1'234'567'990'123ull, GPIOEVENT_EVENT_FALLING_EDGE);
  GpioEdge edge;
  REQUIRE(reader.wait(edge, 0.5) == GpioWait::Edge);
  CHECK(edge.t_s == 1234.0 + 567'890'123 * 1e-9);
  CHECK(edge.kind == GpioEdgeKind::Rising);
  REQUIRE(reader.wait(edge, 0.5) == GpioWait::Edge);
  CHECK(edge.t_s == 1234.0 + 567'990'123 * 1e-9);
  CHECK(edge.kind == GpioEdgeKind::Falling);
  CHECK(reader.edges() == 2);
  CHECK(reader.wait(edge, 0.01) == GpioWait::Timeout);
  CHECK(reader.wait(edge, 0) == GpioWait::Timeout);
}

TEST_CASE("a truncated event or a closed descriptor is an error naming the line, not a hang", "[hw][gpio]") {
  EventPipe pipe;
  GpioEventFdReader reader(pipe.fds[0], "GPIO test line 3");
  const char garbage[5] = {1, 2, 3, 4, 5};
  REQUIRE(::write(pipe.fds[1], garbage, sizeof garbage) == 5);
  GpioEdge edge;
  REQUIRE(reader.wait(edge, 0.5) == GpioWait::Error);
  CHECK_THAT(std::string(reader.last_error()), Catch::Contains("GPIO test line 3") && Catch::Contains("edge event"));
  pipe.close_writer();
  CHECK(reader.wait(edge, -1) == GpioWait::Error);  // waits forever only while the line exists
  CHECK(reader.edges() == 0);
}

TEST_CASE("on this kernel, a missing GPIO chip gives a clear error for output and input", "[hw][gpio]") {
  GpioLineOptions options;
  options.chip = "gpiochip_epichead_absent";
  options.offset = 3;
  const auto output = GpiodOutput::open(options);
  REQUIRE_FALSE(output);
  CHECK_THAT(output.error(), Catch::Contains("'gpiochip_epichead_absent'") && Catch::Contains("cannot open"));
  const auto input = GpiodEdgeInput::open(options, GpioEdges::Both);
  REQUIRE_FALSE(input);
  CHECK_THAT(input.error(), Catch::Contains("'gpiochip_epichead_absent'"));
  options.chip = "/dev/null";  // a path that is no GPIO chip
  const auto not_a_chip = GpiodOutput::open(options);
  REQUIRE_FALSE(not_a_chip);
  CHECK_THAT(not_a_chip.error(), Catch::Contains("'/dev/null'"));
}
