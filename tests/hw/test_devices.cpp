// Driver tests against real kernel devices: vcan (SocketCAN), vivid (V4L2), gpio-sim (libgpiod)
// and uhid (hidapi). This machine's kernel has none of them, so each test looks for its device
// and, when it is absent, WARNs and returns (a pass that says it did not run). The VM of
// tests/vm (docs/vm.md) loads the modules and runs this binary as
// `EPICHEAD_REQUIRE_DEVICES=vcan,vivid,uhid[,gpio-sim] epichead_test_hw_devices "[device]"`:
// a device named there that is missing fails instead of skipping.
// Overrides: EPICHEAD_TEST_VCAN (default vcan0), EPICHEAD_TEST_VIDEO (default: the first vivid
// capture node), gpio-sim is found under /sys/devices/platform/gpio-sim.*, uhid at /dev/uhid.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/uhid.h>
#include <linux/videodev2.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "epichead/firmware_iface/hid_imu_report.h"
#include "epichead/hw/gpiod_edge_input.h"
#include "epichead/hw/gpiod_output.h"
#include "epichead/hw/hid_imu_reader.h"
#include "epichead/hw/socketcan_bus.h"
#include "epichead/hw/v4l2_camera.h"

using namespace epichead::hw;
namespace fs = std::filesystem;

namespace {

std::string env_or(const char* name, const std::string& fallback) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != 0 ? value : fallback;
}

// True when EPICHEAD_REQUIRE_DEVICES (comma-separated) names `device`: the VM sets it so that a
// module that failed to load shows up as a failure, not as a quiet skip.
bool device_required(const std::string& device) {
  std::istringstream list(env_or("EPICHEAD_REQUIRE_DEVICES", ""));
  for (std::string item; std::getline(list, item, ',');)
    if (item == device) return true;
  return false;
}

// Reports a missing device: a failure when it is required, else a warning (the caller returns).
void device_absent(const std::string& device, const std::string& why) {
  if (device_required(device)) FAIL(device << " is required (EPICHEAD_REQUIRE_DEVICES) but absent: " << why);
  WARN(why);
}

std::int64_t now_ns(clockid_t clock) {
  timespec ts{};
  ::clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The vcan interface to test on; when there is none, reports it (device_absent) and the caller
// returns.
std::optional<std::string> vcan_interface() {
  const std::string name = env_or("EPICHEAD_TEST_VCAN", "vcan0");
  if (!fs::exists("/sys/class/net/" + name)) {
    device_absent("vcan", "no vcan interface " + name + " (modprobe vcan; ip link add " + name + " type vcan; ip link set " +
                              name + " up): not run");
    return std::nullopt;
  }
  return name;
}

CanFrame data_frame(std::uint32_t id, std::uint8_t first) {
  CanFrame f;
  f.id = id;
  f.len = 8;
  for (int i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(first + i);
  return f;
}

std::optional<std::string> vivid_node() {
  if (const char* forced = std::getenv("EPICHEAD_TEST_VIDEO")) return std::string(forced);
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator("/dev", ec)) {
    const std::string path = entry.path().string();
    if (path.rfind("/dev/video", 0) != 0) continue;
    const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK);
    if (fd < 0) continue;
    v4l2_capability cap{};
    const bool vivid_capture = ::ioctl(fd, VIDIOC_QUERYCAP, &cap) == 0 &&
                               std::strcmp(reinterpret_cast<const char*>(cap.driver), "vivid") == 0 &&
                               (cap.device_caps & V4L2_CAP_VIDEO_CAPTURE);
    ::close(fd);
    if (vivid_capture) return path;
  }
  return std::nullopt;
}

// vivid's "Disconnect" button emulates an unplug until every file handle is closed.
bool press_vivid_disconnect(const std::string& node) {
  const int fd = ::open(node.c_str(), O_RDWR | O_NONBLOCK);
  if (fd < 0) return false;
  v4l2_queryctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  bool pressed = false;
  while (::ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
    if (std::strcmp(reinterpret_cast<const char*>(q.name), "Disconnect") == 0) {
      v4l2_control c{q.id, 1};
      pressed = ::ioctl(fd, VIDIOC_S_CTRL, &c) == 0;
      break;
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  ::close(fd);
  return pressed;
}

// The gpio-sim bank's chip name and sysfs folder (sim_gpioN/{pull,value} live there).
struct GpioSim {
  std::string chip;
  fs::path sysfs;
};
std::optional<GpioSim> find_gpio_sim() {
  std::error_code ec;
  for (const auto& dev : fs::directory_iterator("/sys/devices/platform", ec)) {
    if (dev.path().filename().string().rfind("gpio-sim", 0) != 0) continue;
    for (const auto& chip : fs::directory_iterator(dev.path(), ec)) {
      const std::string name = chip.path().filename().string();
      if (name.rfind("gpiochip", 0) == 0 && fs::exists(chip.path() / "sim_gpio1")) return GpioSim{name, chip.path()};
    }
  }
  return std::nullopt;
}

// When the gpio-sim module is loaded but no bank is configured, makes one with 4 lines through
// configfs for the test's duration (Documentation/admin-guide/gpio/gpio-sim.rst).
struct GpioSimBank {
  fs::path device = "/sys/kernel/config/gpio-sim/epichead_test";
  bool made = false;
  GpioSimBank() {
    std::error_code ec;
    if (!fs::exists(device.parent_path()) || find_gpio_sim() || !fs::create_directory(device, ec)) return;
    made = true;
    if (!fs::create_directory(device / "bank0", ec)) return;
    std::ofstream(device / "bank0" / "num_lines") << "4";
    std::ofstream(device / "live") << "1";
  }
  ~GpioSimBank() {
    if (!made) return;
    std::ofstream(device / "live") << "0";
    std::error_code ec;
    fs::remove(device / "bank0", ec);
    fs::remove(device, ec);
  }
};

std::string read_line(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

bool uhid_write(int fd, const uhid_event& event) {
  return ::write(fd, &event, sizeof event) == static_cast<ssize_t>(sizeof event);
}

}  // namespace

TEST_CASE("vcan: frames pass between two buses with kernel stamps, filters and no loss or reordering",
          "[hw][device][socketcan]") {
  const auto name = vcan_interface();
  if (!name) return;
  SocketCanOptions all;
  all.interface = *name;
  SocketCanOptions only_0x123 = all;
  only_0x123.filters = {{0x123, 0x7FF, CanIdFormat::Standard}};
  auto sender = SocketCanBus::open(all);
  auto receiver = SocketCanBus::open(all);
  auto filtered = SocketCanBus::open(only_0x123);
  REQUIRE(sender);
  REQUIRE(receiver);
  REQUIRE(filtered);

  const std::int64_t before_us = now_ns(CLOCK_REALTIME) / 1000;
  REQUIRE((*sender)->send(data_frame(0x321, 1)));
  REQUIRE((*sender)->send(data_frame(0x123, 9)));
  StampedCanFrame got;
  REQUIRE((*receiver)->receive(got, 1.0) == CanReceive::Frame);
  CHECK(got.frame.id == 0x321);
  CHECK(got.frame.data[7] == 8);
  CHECK(got.stamp_us >= before_us);
  CHECK(got.stamp_us <= now_ns(CLOCK_REALTIME) / 1000);
  REQUIRE((*receiver)->receive(got, 1.0) == CanReceive::Frame);
  CHECK(got.frame.id == 0x123);
  REQUIRE((*filtered)->receive(got, 1.0) == CanReceive::Frame);
  CHECK(got.frame.id == 0x123);  // 0x321 filtered out
  CHECK((*filtered)->receive(got, 0.05) == CanReceive::Timeout);

  // A flood: vcan hands a frame to every socket at once (there is no bit rate to pace the
  // sender), so the sender sends bursts no larger than the receive queue holds and the receiver
  // drains each; every frame arrives, in order, with non-decreasing kernel stamps.
  constexpr int kFlood = 5000, kBurst = 50;
  int received = 0, out_of_order = 0, stamp_regressions = 0;
  std::int64_t last_stamp_us = 0;
  for (int sent = 0; sent < kFlood;) {
    const int burst_end = std::min(sent + kBurst, kFlood);
    for (; sent < burst_end; ++sent) REQUIRE((*sender)->send(data_frame(0x100 + (sent % 0x100), static_cast<std::uint8_t>(sent))));
    for (; received < burst_end; ++received) {
      REQUIRE((*receiver)->receive(got, 1.0) == CanReceive::Frame);
      if (got.frame.id != static_cast<std::uint32_t>(0x100 + (received % 0x100)) ||
          got.frame.data[0] != static_cast<std::uint8_t>(received))
        ++out_of_order;
      if (got.stamp_us < last_stamp_us) ++stamp_regressions;
      last_stamp_us = got.stamp_us;
    }
  }
  CHECK(out_of_order == 0);
  CHECK(stamp_regressions == 0);
  CHECK((*receiver)->receive(got, 0.05) == CanReceive::Timeout);  // nothing extra, nothing duplicated
  CHECK((*receiver)->stats().rx_dropped == 0);
  CHECK((*receiver)->stats().rx_frames == static_cast<std::uint64_t>(kFlood) + 2);
  CHECK((*sender)->stats().tx_frames == static_cast<std::uint64_t>(kFlood) + 2);
}

TEST_CASE("vcan: frames the kernel drops for a full receive queue are counted, the rest stay in order",
          "[hw][device][socketcan]") {
  const auto name = vcan_interface();
  if (!name) return;
  SocketCanOptions options;
  options.interface = *name;
  auto sender = SocketCanBus::open(options);
  auto receiver = SocketCanBus::open(options);
  REQUIRE(sender);
  REQUIRE(receiver);
  // Far more than a default receive buffer (net.core.rmem_default) holds, sent before reading.
  constexpr int kFrames = 3000;
  for (int i = 0; i < kFrames; ++i) REQUIRE((*sender)->send(data_frame(0x200, static_cast<std::uint8_t>(i))));
  StampedCanFrame got;
  int received = 0, out_of_order = 0;
  std::uint8_t previous = 0;
  while ((*receiver)->receive(got, 0.2) == CanReceive::Frame) {
    // The queue keeps the first frames and drops the rest, so the kept ones are 0, 1, 2, ...
    if (received > 0 && got.frame.data[0] != static_cast<std::uint8_t>(previous + 1)) ++out_of_order;
    previous = got.frame.data[0];
    ++received;
  }
  CHECK(received < kFrames);
  CHECK(out_of_order == 0);
  // The kernel reports its drop total (SO_RXQ_OVFL) on the next frame it queues after the drops,
  // not on the frames queued before them: one more frame brings the count.
  REQUIRE((*sender)->send(data_frame(0x201, 0)));
  REQUIRE((*receiver)->receive(got, 1.0) == CanReceive::Frame);
  CHECK(got.frame.id == 0x201);
  INFO("received " << received << ", dropped " << (*receiver)->stats().rx_dropped);
  CHECK((*receiver)->stats().rx_frames == static_cast<std::uint64_t>(received) + 1);
  CHECK((*receiver)->stats().rx_dropped == static_cast<std::uint64_t>(kFrames - received));
}

TEST_CASE("vcan: an error frame on the bus reaches the driver and sets bus-off", "[hw][device][socketcan]") {
  const auto name = vcan_interface();
  if (!name) return;
  SocketCanOptions options;
  options.interface = *name;
  auto bus = SocketCanBus::open(options);
  REQUIRE(bus);
  // The driver refuses to send error frames, so a plain socket injects one, as a controller would.
  const int raw = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  REQUIRE(raw >= 0);
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(if_nametoindex(name->c_str()));
  REQUIRE(::bind(raw, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0);
  can_frame error{};
  error.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  error.len = CAN_ERR_DLC;
  const bool injected = ::write(raw, &error, sizeof error) == static_cast<ssize_t>(sizeof error);
  ::close(raw);
  if (!injected) {
    device_absent("vcan", "this kernel refuses error frames from user space: bus-off path not run");
    return;
  }
  StampedCanFrame got;
  REQUIRE((*bus)->receive(got, 1.0) == CanReceive::Frame);
  CHECK(got.frame.error());
  CHECK((*bus)->stats().state == CanBusState::BusOff);
  CHECK((*bus)->stats().bus_off_events == 1);
}

TEST_CASE("vivid: the V4L2 driver streams stamped frames and survives an emulated unplug", "[hw][device][v4l2]") {
  const auto node = vivid_node();
  if (!node) {
    device_absent("vivid", "no vivid capture device (modprobe vivid): not run");
    return;
  }
  V4l2CameraOptions options;
  options.device = *node;
  options.formats = {fourcc('Y', 'U', 'Y', 'V'), fourcc('R', 'G', 'B', '3')};
  options.reconnect_interval_s = 0.1;
  options.frame_rate_hz = 10;  // one of vivid's webcam intervals (1/10 s)
  auto opened = V4l2Camera::open(options);
  REQUIRE(opened);
  auto& camera = **opened;
  REQUIRE(camera.start());
  CameraFrame frame;
  double last_t_s = 0, first_t_s = 0;
  std::uint64_t last_sequence = 0, first_sequence = 0;
  for (int i = 0; i < 10; ++i) {
    REQUIRE(camera.next_frame(frame, 2.0) == CameraRead::Frame);
    CHECK(frame.width > 0);
    CHECK(frame.size_bytes >= static_cast<std::size_t>(frame.stride_bytes) * frame.height);
    CHECK(frame.t_s > last_t_s);
    if (i > 0) REQUIRE(frame.sequence > last_sequence);
    if (i == 0) {
      first_t_s = frame.t_s;
      first_sequence = frame.sequence;
    }
    last_sequence = frame.sequence;
    // On the monotonic clock's time base. vivid stamps a modelled end of exposure (0.9 frame
    // periods after the frame's scheduled start), which may lie a little after delivery, so the
    // stamp is only bounded to within a second of now (a wall-clock stamp would be 1e9 s off).
    CHECK(std::abs(frame.t_s - monotonic_clock().now_s()) < 1.0);
    last_t_s = frame.t_s;
  }
  CHECK(camera.stats().unstamped_frames == 0);
  // The rate asked is the one streamed: vivid stamps frames on its own schedule (about start +
  // sequence / rate; single spacings jitter by milliseconds in a loaded VM), and late frames
  // skip sequence numbers, so the mean period per sequence step is checked.
  CHECK((last_t_s - first_t_s) / static_cast<double>(last_sequence - first_sequence) == Approx(0.1).epsilon(0.05));

  if (!press_vivid_disconnect(*node)) {
    device_absent("vivid", "vivid has no Disconnect control here: unplug path not run");
    return;
  }
  CameraRead r = CameraRead::Frame;
  for (int i = 0; i < 100 && r == CameraRead::Frame; ++i) r = camera.next_frame(frame, 1.0);
  REQUIRE(r == CameraRead::Lost);
  bool back = false;
  for (int i = 0; i < 50 && !back; ++i) back = camera.next_frame(frame, 0.2) == CameraRead::Frame;
  CHECK(back);
  CHECK(camera.stats().reconnects == 1);
}

TEST_CASE("gpio-sim: the trigger output drives the line and the sync input stamps edges", "[hw][device][gpio]") {
  const GpioSimBank bank;
  const auto sim = find_gpio_sim();
  if (!sim) {
    device_absent("gpio-sim", "no gpio-sim chip with 2 lines (modprobe gpio-sim; configfs at /sys/kernel/config): not run");
    return;
  }
  GpioLineOptions out_line;
  out_line.chip = sim->chip;
  out_line.offset = 0;
  auto output = GpiodOutput::open(out_line);
  REQUIRE(output);
  REQUIRE((*output)->set(GpioLevel::Active));
  CHECK(read_line(sim->sysfs / "sim_gpio0" / "value") == "1");
  REQUIRE((*output)->set(GpioLevel::Inactive));
  CHECK(read_line(sim->sysfs / "sim_gpio0" / "value") == "0");

  GpioLineOptions in_line = out_line;
  in_line.offset = 1;
  std::ofstream(sim->sysfs / "sim_gpio1" / "pull") << "pull-down";
  auto input = GpiodEdgeInput::open(in_line, GpioEdges::Both);
  REQUIRE(input);
  const double before_s = monotonic_clock().now_s();
  std::ofstream(sim->sysfs / "sim_gpio1" / "pull") << "pull-up";
  GpioEdge edge;
  REQUIRE((*input)->wait_edge(edge, 1.0) == GpioWait::Edge);
  CHECK(edge.kind == GpioEdgeKind::Rising);
  CHECK(edge.t_s >= before_s);
  CHECK(edge.t_s <= monotonic_clock().now_s());
  std::ofstream(sim->sysfs / "sim_gpio1" / "pull") << "pull-down";
  REQUIRE((*input)->wait_edge(edge, 1.0) == GpioWait::Edge);
  CHECK(edge.kind == GpioEdgeKind::Falling);
}

TEST_CASE("uhid: the hidapi reader decodes reports from a device with the IMU's descriptor", "[hw][device][hid]") {
  const int uhid = ::open("/dev/uhid", O_RDWR | O_CLOEXEC);
  if (uhid < 0) {
    device_absent("uhid", "no /dev/uhid (modprobe uhid): not run");
    return;
  }
  namespace fw = epichead::firmware_iface;
  HidImuOptions options;
  options.device.vendor_id = 0x1209;
  options.device.product_id = 0xE1A1;
  uhid_event create{};
  create.type = UHID_CREATE2;
  std::strcpy(reinterpret_cast<char*>(create.u.create2.name), "epichead test IMU");
  create.u.create2.rd_size = static_cast<std::uint16_t>(fw::kHidImuReportDescriptor.size());
  create.u.create2.bus = 0x03;  // BUS_USB
  create.u.create2.vendor = options.device.vendor_id;
  create.u.create2.product = options.device.product_id;
  std::memcpy(create.u.create2.rd_data, fw::kHidImuReportDescriptor.data(), fw::kHidImuReportDescriptor.size());
  REQUIRE(uhid_write(uhid, create));

  // The hidraw node appears asynchronously.
  std::expected<std::unique_ptr<HidImuReader>, std::string> reader = std::unexpected("not tried");
  for (int i = 0; i < 50 && !reader; ++i) {
    reader = HidImuReader::open(options);
    if (!reader) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  INFO((reader.has_value() ? std::string() : reader.error()));
  REQUIRE(reader);

  for (std::uint8_t k = 0; k < 5; ++k) {
    fw::ImuSample s;
    s.counter = k;
    s.stamp_us = 1000u * k;
    s.gyro_radps = {0.1 * k, 0, 0};
    const auto report = fw::encode_hid_imu_report(s);
    REQUIRE(report);
    uhid_event input{};
    input.type = UHID_INPUT2;
    input.u.input2.size = static_cast<std::uint16_t>(report->bytes.size());
    std::memcpy(input.u.input2.data, report->bytes.data(), report->bytes.size());
    REQUIRE(uhid_write(uhid, input));
  }
  ImuReading reading;
  for (std::uint8_t k = 0; k < 5; ++k) {
    REQUIRE((*reader)->receive(reading, 1.0) == ImuRead::Sample);
    CHECK(reading.sample.counter == k);
    CHECK(reading.sample.stamp_us == 1000u * k);
    CHECK(reading.sample.gyro_radps[0] == Approx(0.1 * k).margin(fw::kGyroRadpsPerLsb));
  }
  CHECK((*reader)->stats().lost_samples == 0);

  uhid_event destroy{};
  destroy.type = UHID_DESTROY;
  REQUIRE(uhid_write(uhid, destroy));
  ::close(uhid);
  CHECK((*reader)->receive(reading, 1.0) == ImuRead::Lost);
}
