#pragma once
// The camera port: frames as plain image buffers (no OpenCV here; the head loop wraps them),
// stamped on the program's monotonic clock. Implemented by the V4L2 driver on the robot and by
// the simulator's renderer. A camera that disappears is reported once (Lost) and then
// reconnected by the implementation while the caller keeps asking for frames.
#include <cstddef>
#include <cstdint>
#include <expected>
#include <string>
#include <string_view>

#include "epichead/hw/pixel_format.h"

namespace epichead::hw {

struct CameraFrame {
  int width = 0, height = 0;
  int stride_bytes = 0;                 // bytes from one row to the next (>= width * bytes per pixel)
  PixelFormat format = PixelFormat::Other;
  std::uint32_t fourcc = 0;             // the device's code (names formats PixelFormat does not)
  const std::uint8_t* data = nullptr;   // valid until the next next_frame(), stop() or destruction
  std::size_t size_bytes = 0;           // bytes of image at data (for MJPEG: the JPEG's size)
  double t_s = 0;                       // capture time, program monotonic clock
  std::uint64_t sequence = 0;           // device frame counter; a gap means frames were dropped
};

enum class CameraRead {
  Frame,    // `out` holds a frame
  Timeout,  // no frame within the timeout (still streaming or still reconnecting)
  Lost,     // the device went away now; the camera reconnects on later calls
  Error,    // not streaming (never started, or stopped): see last_error()
};

enum class CameraState {
  Stopped,       // opened, not streaming
  Streaming,     // frames flowing
  Reconnecting,  // the device disappeared; reopening at the configured interval
};

struct CameraStats {
  std::uint64_t frames = 0;          // frames delivered
  std::uint64_t dropped_frames = 0;  // gaps in the device's sequence numbers
  std::uint64_t corrupt_frames = 0;  // buffers flagged bad or shorter than the image; requeued
  std::uint64_t unstamped_frames = 0;  // no usable device stamp: stamped on arrival instead
  std::uint64_t disconnects = 0;     // times the device went away while streaming
  std::uint64_t reconnects = 0;      // times it was reopened and streams again
  std::uint64_t reconnect_attempts = 0;
};

class CameraPort {
 public:
  virtual ~CameraPort() = default;
  virtual std::expected<void, std::string> start() = 0;
  virtual void stop() = 0;
  // Waits up to timeout_s (0: do not wait; negative: forever) for the next frame.
  virtual CameraRead next_frame(CameraFrame& out, double timeout_s) = 0;
  virtual CameraState state() const = 0;
  virtual CameraStats stats() const = 0;
  // Why the last call failed, or why the device was lost (empty if nothing went wrong).
  virtual std::string_view last_error() const = 0;
};

std::string_view to_string(CameraState state);

}  // namespace epichead::hw
