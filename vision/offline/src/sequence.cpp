#include "epichead/vision/offline/sequence.h"

#include <cmath>
#include <filesystem>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "csv_rows.h"

namespace epichead::vision {
namespace {

using Error = std::unexpected<std::string>;
namespace fs = std::filesystem;

const std::vector<std::string_view> kImuColumns{"t_s", "gx", "gy", "gz", "ax", "ay", "az"};
const std::vector<std::string_view> kFrameColumns{"frame", "t_s", "file"};

bool is_file(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// Frames OpenCV reports for a video; when the container does not say, counts them by grabbing
// (which consumes the capture: it is released so that the first read re-opens it).
long long count_video_frames(cv::VideoCapture& capture) {
  const double reported = capture.get(cv::CAP_PROP_FRAME_COUNT);
  if (std::isfinite(reported) && reported > 0 && reported < 1e9) return static_cast<long long>(reported);
  long long n = 0;
  while (capture.grab()) ++n;
  capture.release();
  return n;
}

// Opens a video file with FFmpeg, which reads every common container. Other backends are tried
// only when OpenCV was built without FFmpeg: GStreamer, OpenCV's fallback, leaks memory and logs
// assertion failures on files it cannot parse.
bool open_video(cv::VideoCapture& capture, const std::string& path) {
  const int api = cv::videoio_registry::hasBackend(cv::CAP_FFMPEG) ? cv::CAP_FFMPEG : cv::CAP_ANY;
  return capture.open(path, api);
}

}  // namespace

// The open video and the index of the frame its next read() returns, so that sequential
// reads decode each frame once.
struct Sequence::VideoReader {
  cv::VideoCapture capture;
  std::size_t next = 0;
};

Sequence::Sequence() = default;
Sequence::Sequence(Sequence&&) noexcept = default;
Sequence& Sequence::operator=(Sequence&&) noexcept = default;
Sequence::~Sequence() = default;

std::expected<Sequence, std::string> Sequence::open(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Error(dir + ": not a directory");
  Sequence seq;
  seq.dir_ = dir;
  const std::string base = dir + "/";

  // The calibration under the names people give it: OpenCV's samples write .yml, ROS's
  // camera_calibration camera_info.yaml. Two of them would leave it to chance: an error.
  std::vector<std::string> calibrations;
  for (const char* name : kCameraFileNames)
    if (is_file(base + name)) calibrations.push_back(name);
  if (calibrations.size() > 1)
    return Error(dir + ": holds both " + calibrations[0] + " and " + calibrations[1] + "; keep the one calibration");
  seq.camera_file_ = base + (calibrations.empty() ? kCameraFileNames[0] : calibrations[0]);
  auto camera = Camera::load(seq.camera_file_);
  if (!camera) return Error(camera.error());
  seq.camera_ = std::move(*camera);

  auto model = load_cao(base + "model.cao");
  if (!model) return Error(model.error());
  seq.model_ = std::move(*model);

  // Without init.csv the tracker finds the object itself (detector.h).
  if (is_file(base + "init.csv")) {
    auto init = read_pose_csv(base + "init.csv");
    if (!init) return Error(init.error());
    if (init->size() != 1)
      return Error(base + "init.csv: expected exactly one pose row, got " + std::to_string(init->size()));
    seq.init_ = init->front();
    seq.has_init_ = true;
  }

  if (is_file(base + "gt.csv")) {
    auto gt = read_pose_csv(base + "gt.csv");
    if (!gt) return Error(gt.error());
    seq.gt_ = std::move(*gt);
  }
  if (is_file(base + "imu.csv")) {
    auto imu = read_imu_csv(base + "imu.csv");
    if (!imu) return Error(imu.error());
    seq.imu_ = std::move(*imu);
  }

  const std::string video_path = base + "video.mp4";
  bool from_video = false;
  if (is_file(base + "frames.csv")) {
    auto frames = read_frames_csv(base + "frames.csv");
    if (!frames) return Error(frames.error());
    if (frames->empty()) return Error(base + "frames.csv: lists no frames");
    std::size_t from_files = 0;
    for (const FrameEntry& f : *frames) {
      if (f.file.empty()) continue;
      ++from_files;
      if (!is_file(base + f.file))
        return Error(base + f.file + ": frame file not found (frame " + std::to_string(f.frame) + " in " + base +
                     "frames.csv)");
    }
    if (from_files != 0 && from_files != frames->size())
      return Error(base + "frames.csv: mixes image files and empty file fields (video frames); use one or the other");
    from_video = from_files == 0;
    if (from_video && !is_file(video_path))
      return Error(base + "frames.csv: the file column is empty (frames from video.mp4), but " + video_path +
                   " does not exist");
    seq.frames_ = std::move(*frames);
  } else if (is_file(video_path)) {
    from_video = true;
  } else {
    return Error(dir + ": no frames (neither frames.csv nor video.mp4)");
  }

  if (from_video) {
    auto reader = std::make_unique<VideoReader>();
    try {
      open_video(reader->capture, video_path);
    } catch (const cv::Exception& e) {
      return Error(video_path + ": OpenCV cannot open it (" + e.err + ")");
    }
    if (!reader->capture.isOpened()) return Error(video_path + ": OpenCV cannot open it (unknown container or codec?)");
    if (seq.frames_.empty()) {
      const double fps = reader->capture.get(cv::CAP_PROP_FPS);
      if (!(std::isfinite(fps) && fps > 0)) return Error(video_path + ": OpenCV reports no frame rate");
      const long long n = count_video_frames(reader->capture);
      if (n <= 0) return Error(video_path + ": no frames could be read");
      seq.frames_.resize(static_cast<std::size_t>(n));
      for (std::size_t i = 0; i < seq.frames_.size(); ++i)
        seq.frames_[i] = {static_cast<int>(i), static_cast<double>(i) / fps, {}};
    } else {
      const double reported = reader->capture.get(cv::CAP_PROP_FRAME_COUNT);
      if (std::isfinite(reported) && reported > 0 && static_cast<double>(seq.frames_.size()) > reported)
        return Error(base + "frames.csv: lists " + std::to_string(seq.frames_.size()) + " frames but " + video_path +
                     " has " + std::to_string(static_cast<long long>(reported)));
    }
    seq.video_ = std::move(reader);
  }
  return seq;
}

// A calibration is for one image size: frames of another size would be tracked with the wrong
// intrinsics, silently (most frames lost, or a wrong pose).
std::expected<void, std::string> Sequence::check_size(const cv::Mat& image, const std::string& what) const {
  if (image.cols == camera_.width_px() && image.rows == camera_.height_px()) return {};
  return Error(what + ": the image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) + " but " +
               camera_file_ + " is a calibration for " + std::to_string(camera_.width_px()) + "x" +
               std::to_string(camera_.height_px()));
}

std::expected<cv::Mat, std::string> Sequence::read_frame(std::size_t index) {
  if (index >= frames_.size())
    return Error(dir_ + ": frame index " + std::to_string(index) + " out of range (" + std::to_string(frames_.size()) +
                 " frames)");
  const FrameEntry& entry = frames_[index];
  if (!entry.file.empty()) {
    const std::string path = dir_ + "/" + entry.file;
    cv::Mat image;
    try {
      image = cv::imread(path, cv::IMREAD_COLOR);
    } catch (const cv::Exception& e) {
      return Error(path + ": cannot decode image (" + e.err + ")");
    }
    if (image.empty()) return Error(path + ": cannot read or decode image (frame " + std::to_string(entry.frame) + ")");
    if (auto ok = check_size(image, path); !ok) return Error(ok.error());
    return image;
  }

  // Video: frames are taken in order, so position `index` is the index-th decoded frame.
  const std::string path = dir_ + "/video.mp4";
  try {
    if (!video_ || !video_->capture.isOpened() || video_->next > index) {
      if (!video_) video_ = std::make_unique<VideoReader>();
      video_->capture.release();
      video_->next = 0;
      if (!open_video(video_->capture, path)) return Error(path + ": OpenCV cannot open it");
    }
    while (video_->next < index) {
      if (!video_->capture.grab()) {
        video_->capture.release();  // its position is unknown now: re-open on the next call
        return Error(path + ": video ended at frame " + std::to_string(video_->next) + " before frame " +
                     std::to_string(index));
      }
      ++video_->next;
    }
    cv::Mat image;
    if (!video_->capture.read(image) || image.empty()) {
      video_->capture.release();
      return Error(path + ": cannot decode frame " + std::to_string(index));
    }
    ++video_->next;
    if (auto ok = check_size(image, path + " frame " + std::to_string(index)); !ok) return Error(ok.error());
    return image;
  } catch (const cv::Exception& e) {
    if (video_) video_->capture.release();
    return Error(path + ": cannot decode frame " + std::to_string(index) + " (" + e.err + ")");
  }
}

std::expected<std::vector<ImuRecord>, std::string> read_imu_csv(const std::string& path) {
  auto table = csv::read(path);
  if (!table) return Error(table.error());
  if (auto header = csv::check_header(*table, kImuColumns); !header) return Error(header.error());
  std::vector<ImuRecord> samples;
  samples.reserve(table->rows.size());
  for (const csv::Row& row : table->rows) {
    const std::string at = csv::where(*table, row);
    if (row.fields.size() != kImuColumns.size())
      return Error(at + "expected " + std::to_string(kImuColumns.size()) + " columns, got " +
                   std::to_string(row.fields.size()));
    double v[7];
    for (std::size_t i = 0; i < kImuColumns.size(); ++i) {
      const auto value = csv::parse_finite(row.fields[i]);
      if (!value) return Error(at + csv::number_problem(kImuColumns[i], row.fields[i]));
      v[i] = *value;
    }
    if (!samples.empty() && !(v[0] > samples.back().t_s))
      return Error(at + "t_s " + row.fields[0] + " is not after the previous sample's (times must increase strictly)");
    samples.push_back({v[0], Eigen::Vector3d(v[1], v[2], v[3]), Eigen::Vector3d(v[4], v[5], v[6])});
  }
  return samples;
}

std::expected<void, std::string> write_imu_csv(const std::string& path, const std::vector<ImuRecord>& samples) {
  std::string text = "t_s,gx,gy,gz,ax,ay,az\n";
  text.reserve(text.size() + samples.size() * 96);
  for (const ImuRecord& s : samples) {
    csv::append_exact(text, s.t_s);
    for (double v : {s.gyro_radps.x(), s.gyro_radps.y(), s.gyro_radps.z(), s.accel_mps2.x(), s.accel_mps2.y(),
                     s.accel_mps2.z()}) {
      text += ',';
      csv::append_exact(text, v);
    }
    text += '\n';
  }
  return csv::write_file(path, text);
}

std::expected<std::vector<FrameEntry>, std::string> read_frames_csv(const std::string& path) {
  auto table = csv::read(path);
  if (!table) return Error(table.error());
  if (auto header = csv::check_header(*table, kFrameColumns); !header) return Error(header.error());
  std::vector<FrameEntry> frames;
  frames.reserve(table->rows.size());
  for (const csv::Row& row : table->rows) {
    const std::string at = csv::where(*table, row);
    if (row.fields.size() != kFrameColumns.size())
      return Error(at + "expected 3 columns, got " + std::to_string(row.fields.size()));
    const auto frame = csv::parse_int(row.fields[0]);
    if (!frame) return Error(at + "frame is not a whole number ('" + row.fields[0] + "')");
    if (*frame < 0) return Error(at + "frame must not be negative, got " + row.fields[0]);
    if (!frames.empty() && *frame <= frames.back().frame)
      return Error(at + (*frame == frames.back().frame ? "duplicate frame " + row.fields[0]
                                                       : "frame " + row.fields[0] + " after frame " +
                                                             std::to_string(frames.back().frame) + " (frames must increase)"));
    const auto t_s = csv::parse_finite(row.fields[1]);
    if (!t_s) return Error(at + csv::number_problem("t_s", row.fields[1]));
    if (!frames.empty() && !(*t_s > frames.back().t_s))
      return Error(at + "t_s " + row.fields[1] + " is not after the previous frame's (times must increase strictly)");
    const std::string& file = row.fields[2];
    if (!file.empty() && fs::path(file).is_absolute())
      return Error(at + "file '" + file + "' must be relative to the sequence directory");
    frames.push_back({*frame, *t_s, file});
  }
  return frames;
}

std::expected<void, std::string> write_frames_csv(const std::string& path, const std::vector<FrameEntry>& frames) {
  std::string text = "frame,t_s,file\n";
  for (const FrameEntry& f : frames) {
    if (f.file.find_first_of(",\r\n") != std::string::npos)
      return Error(path + ": file name of frame " + std::to_string(f.frame) + " contains a comma or line break");
    text += std::to_string(f.frame);
    text += ',';
    csv::append_exact(text, f.t_s);
    text += ',';
    text += f.file;
    text += '\n';
  }
  return csv::write_file(path, text);
}

}  // namespace epichead::vision
