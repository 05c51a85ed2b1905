#include "flow/pyramid.hpp"

#include <algorithm>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "flow/lk_kernels.hpp"

namespace roiflow::flow {

int effective_levels(cv::Size size, int requested) {
  if (requested < 1 || requested > kMaxLevels) {
    throw Error("levels must be in 1.." + std::to_string(kMaxLevels) + ", got " +
                std::to_string(requested));
  }
  int levels = 1;
  while (levels < requested) {
    const cv::Size next = level_size(size, levels);
    if (std::min(next.width, next.height) < kMinLevelSide) break;
    ++levels;
  }
  return levels;
}

cv::Size level_size(cv::Size size, int level) {
  for (int l = 0; l < level; ++l)
    size = cv::Size((size.width + 1) / 2, (size.height + 1) / 2);
  return size;
}

namespace {

// Row y of `image` (8-bit, 16-bit or float gray) scaled to [0, 1] into dst[0 .. cols).
void unit_row(const detail::LkKernels& kernels, const cv::Mat& image, int y, float* dst) {
  const int w = image.cols;
  switch (image.depth()) {
    case CV_8U:
      return kernels.unit_row_u8(image.ptr<std::uint8_t>(y), w, dst);
    case CV_16U: {
      const std::uint16_t* src = image.ptr<std::uint16_t>(y);
      for (int x = 0; x < w; ++x)
        dst[x] = static_cast<float>(src[x]) * (1.f / 65535.f);
      break;
    }
    default:
      std::copy_n(image.ptr<float>(y), w, dst);
  }
}

// cv::pyrDown of a float image whose rows arrive in order (push(y, row) for y = 0 .. h - 1), by
// the kernels' two row steps: each row halved into a ring of 8, and output row j made as soon as
// the rows 2j - 2 .. 2j + 2 it reads (reflected at the borders) are in. The same floats as
// cv::pyrDown.
class RowDownsampler {
 public:
  // Whether the kernels have the row steps and the image is large enough for them.
  static bool available(const detail::LkKernels& kernels, int w, int h) {
    return kernels.pyr_down_h != nullptr && w >= 8 && h >= 3;
  }

  RowDownsampler(const detail::LkKernels& kernels, int w, int h, cv::Mat& dst)
      : kernels_(kernels), w_(w), h_(h), dw_((w + 1) / 2), dst_(dst) {
    dst.create((h + 1) / 2, dw_, CV_32F);
    thread_local std::vector<float> ring;
    ring.resize(static_cast<std::size_t>(8) * dw_);
    ring_ = ring.data();
  }

  void push(int y, const float* row) {
    kernels_.pyr_down_h(row, w_, halved(y));
    for (; next_ < dst_.rows && y >= std::min(2 * next_ + 2, h_ - 1); ++next_) {
      const float* rows[5];
      for (int i = 0; i < 5; ++i) {
        int r = 2 * next_ - 2 + i;
        r = r < 0 ? -r : (r >= h_ ? 2 * h_ - 2 - r : r);
        rows[i] = halved(r);
      }
      kernels_.pyr_down_v(rows, dw_, dst_.ptr<float>(next_));
    }
  }

 private:
  float* halved(int y) const { return ring_ + static_cast<std::size_t>(y & 7) * dw_; }

  const detail::LkKernels& kernels_;
  int w_, h_, dw_;
  cv::Mat& dst_;
  float* ring_ = nullptr;
  int next_ = 0;  // the next output row
};

// dst = cv::pyrDown(src) for a float image (by the kernels where they can).
void pyr_down(const cv::Mat& src, cv::Mat& dst) {
  const detail::LkKernels& kernels = detail::lk_kernels();
  if (src.type() != CV_32FC1 || !RowDownsampler::available(kernels, src.cols, src.rows) ||
      src.data == dst.data) {
    cv::pyrDown(src, dst);
    return;
  }
  RowDownsampler down(kernels, src.cols, src.rows, dst);
  for (int y = 0; y < src.rows; ++y)
    down.push(y, src.ptr<float>(y));
}

// The pretreatment for a kernel of radius R (1..4): `image` in [0, 1], smoothed by the separable
// Gaussian `k` (2R + 1 taps, borders replicated), in one pass over the rows: each row is scaled
// and filtered horizontally into a ring of 2R + 1 rows, and each output row is the vertical sum
// over the ring. Each output pixel depends only on its neighbourhood, never on where the image
// (a part of a frame) starts, so pyramids of parts of a frame equal the whole frame's inside
// them.
//
// With `down`, the next pyramid level is made too (cv::pyrDown of `out`) from each row of `out`
// while it is in the cache; returns whether it was (false: the kernels cannot).
bool smooth_to_unit_float(const cv::Mat& image, const float* k, int R, cv::Mat& out,
                          cv::Mat* down) {
  const detail::LkKernels& kernels = detail::lk_kernels();
  const int taps = 2 * R + 1;
  const int w = image.cols, h = image.rows;
  // Kept per thread: a tracker builds a few small parts every frame.
  thread_local std::vector<float> padded, ring;
  padded.resize(static_cast<std::size_t>(w + 2 * R));
  ring.resize(static_cast<std::size_t>(taps) * w);
  auto filtered = [&](int row) { return ring.data() + static_cast<std::size_t>(row % taps) * w; };
  const float* rows[9];
  out.create(h, w, CV_32F);
  std::optional<RowDownsampler> downsampler;
  if (down && RowDownsampler::available(kernels, w, h)) downsampler.emplace(kernels, w, h, *down);
  // A part of a frame is a few hundred bytes of each of its rows, often not in the cache (a
  // frame just decoded on another core, or one of many in memory): asking for the rows a few
  // ahead of the one filtered keeps the loads from waiting on memory one row at a time. (Inline:
  // GCC takes a function that only prefetches for a pure one and drops its calls.)
  constexpr int kAhead = 8;
  const std::size_t row_bytes = static_cast<std::size_t>(w) * image.elemSize();
  int fetched = 0;  // rows [0, fetched) have been asked for
  int next = 0;     // rows [0, next) are filtered (the ring holds the last `taps` of them)
  for (int y = 0; y < h; ++y) {
    for (; next <= std::min(h - 1, y + R); ++next) {
      for (; fetched < std::min(h, next + kAhead); ++fetched) {
        const std::uint8_t* row = image.ptr<std::uint8_t>(fetched);
        for (std::size_t i = 0; i < row_bytes; i += 64)
          __builtin_prefetch(row + i);
        __builtin_prefetch(row + row_bytes - 1);
      }
      float* p = padded.data();
      unit_row(kernels, image, next, p + R);
      std::fill(p, p + R, p[R]);
      std::fill(p + R + w, p + 2 * R + w, p[R + w - 1]);
      kernels.smooth_h(p, k, R, w, filtered(next));
    }
    for (int j = 0; j < taps; ++j)
      rows[j] = filtered(std::clamp(y - R + j, 0, h - 1));
    kernels.smooth_v(rows, k, R, w, out.ptr<float>(y));
    if (downsampler) downsampler->push(y, out.ptr<float>(y));
  }
  return downsampler.has_value();
}

// Level 0: `image` (8-bit gray or BGR, 16-bit or float gray) as float in [0, 1], smoothed by a
// Gaussian of `sigma` (0 = not at all) with the kernel OpenCV's GaussianBlur takes for float
// images. Up to sigma ~1.1 (radius 4) by the fused pass above: every pyramid of every mode
// starts with it, and at the paper's sigma 0.5 OpenCV's conversion + GaussianBlur take
// 1.7-1.8x as long (bench/flow_bench BM_Pretreatment, VGA and 720p). Wider kernels by OpenCV;
// both compute the same up to float rounding (~2e-7).
//
// With `down`, level 1 is made along with level 0 where the fused pass can (returns whether).
bool base_level(const cv::Mat& image, double sigma, cv::Mat& out, cv::Mat* down) {
  cv::Mat gray;
  switch (image.type()) {
    case CV_8UC1:
    case CV_16UC1:
    case CV_32FC1:
      gray = image;
      break;
    case CV_8UC3:
      cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
      break;
    default:
      throw Error("image type must be 8-bit gray, 8-bit BGR, 16-bit gray or float gray, got " +
                  cv::typeToString(image.type()));
  }
  const int ksize = sigma > 0.0 ? std::max(3, cvRound(sigma * 8 + 1) | 1) : 0;
  if (ksize > 0 && ksize / 2 <= 4) {
    // The kernel of the last sigma, kept per thread (OpenCV computes it in soft floating point).
    thread_local std::pair<double, cv::Mat> kernel;
    if (kernel.second.empty() || kernel.first != sigma) {
      kernel = {sigma, cv::getGaussianKernel(ksize, sigma, CV_32F)};
    }
    return smooth_to_unit_float(gray, kernel.second.ptr<float>(), ksize / 2, out, down);
  }
  out.create(gray.size(), CV_32F);
  const detail::LkKernels& kernels = detail::lk_kernels();
  for (int y = 0; y < gray.rows; ++y)
    unit_row(kernels, gray, y, out.ptr<float>(y));
  if (ksize > 0) {
    cv::GaussianBlur(out, out, cv::Size(ksize, ksize), sigma, sigma, cv::BORDER_REPLICATE);
  }
  return false;
}

void check_sigma(const cv::Mat& image, double sigma) {
  if (image.empty()) throw Error("image is empty");
  if (!(sigma >= 0.0 && sigma <= 20.0)) {
    throw Error("smoothing sigma must be in [0, 20], got " + std::to_string(sigma));
  }
}

}  // namespace

void build_base_level(const cv::Mat& image, int levels, double sigma, Pyramid& out) {
  check_sigma(image, sigma);
  out.levels.resize(effective_levels(image.size(), levels));
  base_level(image, sigma, out.levels[0], nullptr);
}

void build_level(Pyramid& pyr, int level) {
  if (level < 1 || level >= pyr.num_levels()) {
    throw Error("pyramid level " + std::to_string(level) + " is outside 1.." +
                std::to_string(pyr.num_levels() - 1));
  }
  pyr_down(pyr.levels[level - 1], pyr.levels[level]);
}

// Level 1 is made in the pass that makes level 0 (its rows while they are in the cache).
void build_pyramid(const cv::Mat& image, int levels, double sigma, Pyramid& out) {
  check_sigma(image, sigma);
  out.levels.resize(effective_levels(image.size(), levels));
  cv::Mat* down = out.num_levels() > 1 ? &out.levels[1] : nullptr;
  const bool fused = base_level(image, sigma, out.levels[0], down);
  for (int l = fused ? 2 : 1; l < out.num_levels(); ++l)
    build_level(out, l);
}

void build_pyramid_part(const cv::Mat& image, const cv::Rect& rect, int levels, double sigma,
                        Pyramid& out) {
  const int grid = 1 << (std::clamp(levels, 1, kMaxLevels) - 1);
  if (rect.empty() || (rect & cv::Rect(cv::Point(), image.size())) != rect || rect.x % grid != 0 ||
      rect.y % grid != 0) {
    throw Error("pyramid part (" + std::to_string(rect.x) + ", " + std::to_string(rect.y) + ") " +
                std::to_string(rect.width) + "x" + std::to_string(rect.height) +
                " must lie in the " + std::to_string(image.cols) + "x" +
                std::to_string(image.rows) + " image with its origin on a multiple of " +
                std::to_string(grid));
  }
  build_pyramid(image(rect), levels, sigma, out);
}

cv::Rect part_level_rect(const cv::Rect& rect, int level) {
  return {cv::Point(rect.x >> level, rect.y >> level), level_size(rect.size(), level)};
}

Pyramid build_pyramid(const cv::Mat& image, int levels, double sigma) {
  Pyramid pyr;
  build_pyramid(image, levels, sigma, pyr);
  return pyr;
}

}  // namespace roiflow::flow
