#pragma once
// Procedural textures of the built-in scenes (8-bit BGR, gamma-encoded like photos). Every
// generator is seeded: the same arguments give the same pixels.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace epichead::sim::texture {

// Strong-edged clutter for walls: shelves, boxes, pipes, cables, blobs, labels.
cv::Mat clutter(cv::Size size, std::uint64_t seed);

// A weld seam on a plate texture: a straight bead from a to b (texture pixels).
struct Seam { cv::Point2d a, b; };
// Near-white multiplier for a steel plate: faint mottling, mill-scale specks and thin slightly
// darker weld seams (the seams are appearance only, not model edges).
cv::Mat steel_plate(cv::Size size, const std::vector<Seam>& seams, std::uint64_t seed);

// A printed package face: coloured panels, a brand name, text lines, a logo, a barcode, with a
// thin border so the box edges stay visible. `style` picks the layout (0..5).
cv::Mat package_face(cv::Size size, int style, std::uint64_t seed);

// Tileable wood grain (a table top), concrete (a hall floor), painted plaster (walls), woven
// fabric (a lamp shade: near-white multiplier), parquet (an office floor).
cv::Mat wood(cv::Size size, std::uint64_t seed);
cv::Mat concrete(cv::Size size, std::uint64_t seed);
cv::Mat plaster(cv::Size size, cv::Scalar bgr, std::uint64_t seed);
cv::Mat fabric(cv::Size size, std::uint64_t seed);
cv::Mat parquet(cv::Size size, std::uint64_t seed);

}  // namespace epichead::sim::texture
