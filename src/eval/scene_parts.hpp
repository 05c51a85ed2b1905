// The drawing parts the synthetic scenes share (tracking_scene.cpp defines them): seeded
// streams, textured backgrounds, noise octaves and anti-aliased rounded-rectangle masks.
//
//   cv::RNG rng(roiflow::eval::detail::mix(seed, 0));
//   const cv::Mat background = roiflow::eval::detail::draw_background({640, 480}, rng);
//   const cv::Mat alpha = roiflow::eval::detail::rounded_rect_alpha({72, 44}, 9.0);
#pragma once

#include <cstdint>
#include <initializer_list>
#include <opencv2/core.hpp>

namespace roiflow::eval::detail {

// splitmix64: unrelated streams for seeds 1, 2, 3... and for each `stream` of one seed.
std::uint64_t mix(std::uint64_t seed, std::uint64_t stream);
// Adds smoothed noise octaves (cells of the given sizes, amplitude growing with the cell, a
// slight colour tint each) to a CV_32FC3 image.
void add_octaves(cv::Mat& image, cv::RNG& rng, std::initializer_list<int> cells, double gain);
// A static textured background in muted colours with soft shapes (CV_8UC3).
cv::Mat draw_background(cv::Size size, cv::RNG& rng);
// Coverage of the rounded rectangle [0, w) x [0, h) with corner radius r (CV_32FC1, 0..1).
cv::Mat rounded_rect_alpha(cv::Size size, double r);

}  // namespace roiflow::eval::detail
