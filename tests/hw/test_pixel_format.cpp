#include <catch2/catch.hpp>

#include <linux/videodev2.h>

#include "epichead/hw/pixel_format.h"

using namespace epichead::hw;

TEST_CASE("pixel formats use the V4L2 FourCC codes", "[hw][camera]") {
  CHECK(fourcc_of(PixelFormat::Gray8) == V4L2_PIX_FMT_GREY);
  CHECK(fourcc_of(PixelFormat::Yuyv) == V4L2_PIX_FMT_YUYV);
  CHECK(fourcc_of(PixelFormat::Rgb24) == V4L2_PIX_FMT_RGB24);
  CHECK(fourcc_of(PixelFormat::Bgr24) == V4L2_PIX_FMT_BGR24);
  CHECK(fourcc_of(PixelFormat::Mjpeg) == V4L2_PIX_FMT_MJPEG);
  CHECK(pixel_format_from_fourcc(V4L2_PIX_FMT_YUYV) == PixelFormat::Yuyv);
  CHECK(pixel_format_from_fourcc(V4L2_PIX_FMT_NV12) == PixelFormat::Other);
  CHECK(pixel_format_from_fourcc(0) == PixelFormat::Other);
  CHECK(bytes_per_pixel(PixelFormat::Yuyv) == 2);
  CHECK(bytes_per_pixel(PixelFormat::Mjpeg) == 0);
}

TEST_CASE("FourCC text converts both ways and refuses what is not four printable characters", "[hw][camera]") {
  CHECK(fourcc_to_string(V4L2_PIX_FMT_MJPEG) == "MJPG");
  CHECK(fourcc_to_string(0x01020304) == "????");
  CHECK(fourcc_from_string("YUYV") == V4L2_PIX_FMT_YUYV);
  CHECK_FALSE(fourcc_from_string("YUY"));
  CHECK_FALSE(fourcc_from_string("YUYV2"));
  CHECK_FALSE(fourcc_from_string(std::string_view("YU\nV", 4)));
}
