#include "eval/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"

namespace roiflow::eval {
namespace {

constexpr int kMinSide = 8;
constexpr int kMaxSide = 8192;

const cv::Point2d kTranslation{1.3, -0.7};
constexpr double kRotationDeg = 3.0;
constexpr double kZoom = 1.04;
constexpr double kNonRigidAmplitude = 2.0;
const cv::Point2d kBackgroundMotion{0.6, 0.4};
const cv::Point2d kObjectMotion{3.2, 1.5};

// Independent random streams derived from one user seed, so that e.g. the object texture
// does not repeat the background's draws.
enum class Stream : std::uint64_t { Background = 0, Object = 1, Deformation = 2 };

// splitmix64: spreads nearby seeds (1, 2, 3...) over the whole state space of the generator.
std::uint64_t mix_seed(std::uint64_t seed, Stream stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(stream) + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Uniform draws computed by hand from the raw 64-bit output: std::uniform_real_distribution
// is implementation-defined, and the scenes must not change with the standard library.
class Rng {
 public:
  Rng(std::uint64_t seed, Stream stream) : engine_(mix_seed(seed, stream)) {}
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  double sign() { return (engine_() >> 63) != 0 ? 1.0 : -1.0; }

 private:
  std::mt19937_64 engine_;
};

// sin(x), branch-free and in plain arithmetic so that the compiler vectorises the texture
// loops: std::sin is a library call per sample and dominated the render time (30 sinusoids
// per pixel). Within 1e-11 of std::sin for the arguments used here (|x| < 1e5).
inline double fast_sin(double x) {
  constexpr double kInvPi = 1 / std::numbers::pi;
  // Adding and subtracting 1.5 * 2^52 rounds to the nearest integer without a libm call.
  constexpr double kRound = 0x1.8p52;
  // pi as double plus the remainder that double lacks, so that r keeps its precision.
  constexpr double kPiHi = 3.141592653589793116;
  constexpr double kPiLo = 1.2246467991473532e-16;
  const double n = (x * kInvPi + kRound) - kRound;
  const double r = (x - n * kPiHi) - n * kPiLo;  // in [-pi/2, pi/2]; sin(x) = (-1)^n sin(r)
  const double half = (n * 0.5 + kRound) - kRound;
  const double sign = (n * 0.5 == half) ? 1.0 : -1.0;
  // Taylor series to r^15: the first omitted term is below (pi/2)^17 / 17! ~ 6e-12.
  const double r2 = r * r;
  double p = -1.0 / 1307674368000.0;
  p = p * r2 + 1.0 / 6227020800.0;
  p = p * r2 - 1.0 / 39916800.0;
  p = p * r2 + 1.0 / 362880.0;
  p = p * r2 - 1.0 / 5040.0;
  p = p * r2 + 1.0 / 120.0;
  p = p * r2 - 1.0 / 6.0;
  p = p * r2 + 1.0;
  return sign * r * p;
}

inline double fast_cos(double x) {
  return fast_sin(x + std::numbers::pi / 2);
}

// T(x, y) in (0.05, 0.95): a sum of sinusoids and Gaussian blobs, normalised by its analytic
// standard deviation and squashed by tanh, so it never saturates the 8-bit range whatever
// the draws and stays smooth (no clipping kinks that would break sub-pixel exactness).
class Texture {
 public:
  Texture(std::uint64_t seed, Stream stream, const cv::Rect2d& extent) {
    Rng rng(seed, stream);
    constexpr int kSinusoids = 30;
    constexpr int kBlobs = 20;
    constexpr double kMinWavelength = 4.0;
    constexpr double kMaxWavelength = 60.0;
    double variance = 0;
    for (int i = 0; i < kSinusoids; ++i) {
      // Log-uniform wavelengths with a 1/f amplitude spectrum, like natural images: fine
      // detail for the gradients, but weak enough near the Nyquist limit that bilinear
      // interpolation of the rendered frames stays within a grey level of the texture.
      const double wavelength =
          kMinWavelength * std::pow(kMaxWavelength / kMinWavelength, rng.uniform(0, 1));
      const double angle = rng.uniform(0, 2 * std::numbers::pi);
      const double k = 2 * std::numbers::pi / wavelength;
      const double amplitude = wavelength / kMaxWavelength * rng.uniform(0.5, 1.0);
      kx_.push_back(k * std::cos(angle));
      ky_.push_back(k * std::sin(angle));
      phase_.push_back(rng.uniform(0, 2 * std::numbers::pi));
      amplitude_.push_back(amplitude);
      variance += amplitude * amplitude / 2;
    }
    const double area = std::max(extent.area(), 1.0);
    for (int i = 0; i < kBlobs; ++i) {
      Blob b;
      b.cx = extent.x + extent.width * rng.uniform(0, 1);
      b.cy = extent.y + extent.height * rng.uniform(0, 1);
      const double radius = rng.uniform(3, 25);
      b.inv_two_r2 = 1 / (2 * radius * radius);
      b.amplitude = rng.sign() * rng.uniform(0.5, 1.0);
      b.cutoff_r2 = 2 * kBlobCutoff * radius * radius;
      blobs_.push_back(b);
      // Mean square of a Gaussian bump over the extent: integral of exp(-r^2/R^2) = pi R^2.
      variance += b.amplitude * b.amplitude * std::numbers::pi * radius * radius / area;
    }
    scale_ = kGain / std::sqrt(variance);
  }

  // Samples T at n arbitrary points. Sinusoid-major order keeps the inner loop simple and
  // the coefficients in registers.
  void sample(const double* xs, const double* ys, int n, double* out) const {
    std::fill(out, out + n, 0.0);
    for (std::size_t s = 0; s < kx_.size(); ++s) {
      const double kx = kx_[s], ky = ky_[s], ph = phase_[s], a = amplitude_[s];
      for (int i = 0; i < n; ++i)
        out[i] += a * fast_sin(kx * xs[i] + ky * ys[i] + ph);
    }
    const double floor = std::exp(-kBlobCutoff);
    for (const Blob& b : blobs_) {
      for (int i = 0; i < n; ++i) {
        const double dx = xs[i] - b.cx, dy = ys[i] - b.cy;
        const double r2 = dx * dx + dy * dy;
        // Truncated and lifted so the blob is still continuous at its support's edge.
        if (r2 < b.cutoff_r2) out[i] += b.amplitude * (std::exp(-r2 * b.inv_two_r2) - floor);
      }
    }
    for (int i = 0; i < n; ++i)
      out[i] = 0.5 + 0.45 * std::tanh(out[i] * scale_);
  }

 private:
  // exp(-12) ~ 6e-6: the truncation changes the texture by far less than one grey level.
  static constexpr double kBlobCutoff = 12.0;
  // tanh(kGain * N(0, 1)) has a standard deviation of ~0.55, i.e. ~64 grey levels after the
  // 0.45 squash: strong contrast, while most samples stay in the nearly linear part.
  static constexpr double kGain = 0.75;

  struct Blob {
    double cx = 0, cy = 0, inv_two_r2 = 0, amplitude = 0, cutoff_r2 = 0;
  };
  std::vector<double> kx_, ky_, phase_, amplitude_;
  std::vector<Blob> blobs_;
  double scale_ = 1;
};

void check_size(cv::Size size) {
  if (size.width < kMinSide || size.height < kMinSide || size.width > kMaxSide ||
      size.height > kMaxSide) {
    throw Error("synthetic scene size must be between " + std::to_string(kMinSide) + "x" +
                std::to_string(kMinSide) + " and " + std::to_string(kMaxSide) + "x" +
                std::to_string(kMaxSide) + ", got " + std::to_string(size.width) + "x" +
                std::to_string(size.height));
  }
}

std::uint8_t quantise(double value) {
  return cv::saturate_cast<std::uint8_t>(255.0 * value);
}

// Fills the frame from T at W^-1 of every pixel, a row at a time: `inverse_row(n, xs, ys)`
// receives the n pixel coordinates of a row and replaces them by the points to sample.
template <class InverseRow>
cv::Mat render(const Texture& texture, cv::Size size, InverseRow inverse_row) {
  cv::Mat frame(size, CV_8UC1);
  std::vector<double> xs(size.width), ys(size.width), values(size.width);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      xs[x] = x;
      ys[x] = y;
    }
    inverse_row(size.width, xs.data(), ys.data());
    texture.sample(xs.data(), ys.data(), size.width, values.data());
    auto* row = frame.ptr<std::uint8_t>(y);
    for (int x = 0; x < size.width; ++x)
      row[x] = quantise(values[x]);
  }
  return frame;
}

// Lifts a point map to the row form that render() takes.
template <class Map>
auto pointwise(Map map) {
  return [map](int n, double* xs, double* ys) {
    for (int i = 0; i < n; ++i) {
      const cv::Point2d p = map(cv::Point2d(xs[i], ys[i]));
      xs[i] = p.x;
      ys[i] = p.y;
    }
  };
}

// Ground truth W(x) - x at every pixel of frame0.
template <class Warp>
cv::Mat forward_flow(cv::Size size, Warp warp) {
  cv::Mat flow(size, CV_32FC2);
  for (int y = 0; y < size.height; ++y) {
    auto* row = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < size.width; ++x) {
      const cv::Point2d d = warp(cv::Point2d(x, y)) - cv::Point2d(x, y);
      row[x] = cv::Vec2f(static_cast<float>(d.x), static_cast<float>(d.y));
    }
  }
  return flow;
}

cv::Rect2d background_extent(cv::Size size) {
  // Blobs may sit a little outside the frame: motion brings that border into view.
  const double margin = 0.1 * std::max(size.width, size.height);
  return {-margin, -margin, size.width + 2 * margin, size.height + 2 * margin};
}

template <class Forward, class InverseRow>
Scene make_warped(cv::Size size, std::uint64_t seed, Forward forward, InverseRow inverse_row) {
  const Texture texture(seed, Stream::Background, background_extent(size));
  Scene scene;
  scene.frame0 = render(texture, size, [](int, double*, double*) {});
  scene.frame1 = render(texture, size, inverse_row);
  scene.flow = forward_flow(size, forward);
  return scene;
}

Scene make_rotation(cv::Size size, std::uint64_t seed) {
  // Counter-clockwise on screen: with y pointing down, a point right of the centre moves up.
  const cv::Point2d c((size.width - 1) / 2.0, (size.height - 1) / 2.0);
  const double theta = kRotationDeg * std::numbers::pi / 180;
  const double cs = std::cos(theta), sn = std::sin(theta);
  const auto rotate = [c](cv::Point2d p, double cos_t, double sin_t) {
    const cv::Point2d d = p - c;
    return c + cv::Point2d(cos_t * d.x + sin_t * d.y, -sin_t * d.x + cos_t * d.y);
  };
  return make_warped(
      size, seed, [&](cv::Point2d p) { return rotate(p, cs, sn); },
      pointwise([&](cv::Point2d p) { return rotate(p, cs, -sn); }));
}

Scene make_zoom(cv::Size size, std::uint64_t seed) {
  const cv::Point2d c((size.width - 1) / 2.0, (size.height - 1) / 2.0);
  return make_warped(
      size, seed, [c](cv::Point2d p) { return c + kZoom * (p - c); },
      pointwise([c](cv::Point2d p) { return c + (1 / kZoom) * (p - c); }));
}

Scene make_nonrigid(cv::Size size, std::uint64_t seed) {
  // d(x) = A (sin(ax x + p0) cos(ay y + p1), cos(bx x + p2) sin(by y + p3)), wavelengths of
  // about half the image but never below 48 px: the Frobenius norm of its Jacobian,
  // A sqrt(ax^2 + ay^2 + bx^2 + by^2), is then < 0.61 even on tiny images, so the fixed-point
  // inversion y <- x - d(y) below is a contraction.
  Rng rng(seed, Stream::Deformation);
  const double two_pi = 2 * std::numbers::pi;
  const double lx = std::max(size.width / 2.0, 48.0), ly = std::max(size.height / 2.0, 48.0);
  const double ax = two_pi / (lx * rng.uniform(0.9, 1.1));
  const double ay = two_pi / (ly * rng.uniform(0.9, 1.1));
  const double bx = two_pi / (lx * rng.uniform(0.7, 0.9));
  const double by = two_pi / (ly * rng.uniform(1.1, 1.3));
  double p[4];
  for (double& v : p)
    v = rng.uniform(0, two_pi);
  const auto d = [=](cv::Point2d q) {
    return kNonRigidAmplitude * cv::Point2d(fast_sin(ax * q.x + p[0]) * fast_cos(ay * q.y + p[1]),
                                            fast_cos(bx * q.x + p[2]) * fast_sin(by * q.y + p[3]));
  };
  // A fixed iteration count from the a-priori bound |y_k - y*| <= L^k |x - y*| <= L^k A sqrt 2
  // instead of a per-pixel convergence test: same 1e-6 accuracy, and a loop without early
  // exits that the compiler can vectorise along the row.
  const double lipschitz = kNonRigidAmplitude * std::sqrt(ax * ax + ay * ay + bx * bx + by * by);
  const int iterations = static_cast<int>(
      std::ceil(std::log(1e-6 / (kNonRigidAmplitude * std::sqrt(2.0))) / std::log(lipschitz)));
  const auto inverse_row = [d, iterations](int n, double* xs, double* ys) {
    std::vector<double> x0(xs, xs + n), y0(ys, ys + n);
    for (int k = 0; k < iterations; ++k) {
      for (int i = 0; i < n; ++i) {
        const cv::Point2d y = cv::Point2d(x0[i], y0[i]) - d(cv::Point2d(xs[i], ys[i]));
        xs[i] = y.x;
        ys[i] = y.y;
      }
    }
  };
  return make_warped(
      size, seed, [d](cv::Point2d q) { return q + d(q); }, inverse_row);
}

// Fraction of the unit pixel square centred at `c` covered by [lo, hi): the exact box-filtered
// edge, i.e. a 1 px anti-aliased boundary.
double coverage(double c, double lo, double hi) {
  return std::clamp(std::min(c + 0.5, hi) - std::max(c - 0.5, lo), 0.0, 1.0);
}

Scene make_moving_object(cv::Size size, std::uint64_t seed) {
  const cv::Size2d object(std::max(size.width / 4.0, 2.0), std::max(size.height / 4.0, 2.0));
  // Left of the centre, with a fractional corner so that its edges are genuinely soft.
  const cv::Point2d origin0(0.3 * size.width - object.width / 2 + 0.37,
                            0.45 * size.height - object.height / 2 + 0.21);
  const Texture background(seed, Stream::Background, background_extent(size));
  // The object texture lives in object coordinates (origin at its top-left corner).
  const Texture foreground(seed, Stream::Object, cv::Rect2d(cv::Point2d(0, 0), object));

  const auto composite = [&](cv::Point2d background_shift, cv::Point2d origin) {
    const double left = origin.x, right = origin.x + object.width;
    const double top = origin.y, bottom = origin.y + object.height;
    // Columns the object touches at all (coverage > 0); elsewhere its texture is not needed.
    const int x0 = std::clamp(static_cast<int>(std::floor(left + 0.5)), 0, size.width);
    const int x1 = std::clamp(static_cast<int>(std::ceil(right + 0.5)), x0, size.width);
    cv::Mat frame(size, CV_8UC1);
    const int w = size.width;
    std::vector<double> xs(w), ys(w), bg(w), fg(w);
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < w; ++x) {
        xs[x] = x - background_shift.x;
        ys[x] = y - background_shift.y;
      }
      background.sample(xs.data(), ys.data(), w, bg.data());
      const double alpha_y = coverage(y, top, bottom);
      if (alpha_y > 0 && x1 > x0) {
        for (int x = x0; x < x1; ++x) {
          xs[x] = x - origin.x;
          ys[x] = y - origin.y;
        }
        foreground.sample(xs.data() + x0, ys.data() + x0, x1 - x0, fg.data() + x0);
      }
      auto* row = frame.ptr<std::uint8_t>(y);
      for (int x = 0; x < w; ++x) {
        const double alpha = alpha_y * coverage(x, left, right);
        row[x] = quantise(alpha > 0 ? alpha * fg[x] + (1 - alpha) * bg[x] : bg[x]);
      }
    }
    return frame;
  };

  Scene scene;
  scene.frame0 = composite({0, 0}, origin0);
  scene.frame1 = composite(kBackgroundMotion, origin0 + kObjectMotion);
  const cv::Rect2d inside(origin0, object);
  scene.flow = forward_flow(size, [&](cv::Point2d p) {
    return p + (inside.contains(p) ? kObjectMotion : kBackgroundMotion);
  });
  return scene;
}

}  // namespace

Scene make_translation(cv::Size size, cv::Point2f motion, std::uint64_t seed) {
  check_size(size);
  // Beyond the largest image side the frames share no content; the bound also keeps the
  // texture's arguments where fast_sin is accurate.
  if (!(std::abs(motion.x) <= kMaxSide && std::abs(motion.y) <= kMaxSide)) {
    throw Error("synthetic translation must be finite and at most " + std::to_string(kMaxSide) +
                " px per axis, got (" + std::to_string(motion.x) + ", " + std::to_string(motion.y) +
                ")");
  }
  const cv::Point2d m(motion.x, motion.y);
  return make_warped(
      size, seed, [m](cv::Point2d p) { return p + m; },
      pointwise([m](cv::Point2d p) { return p - m; }));
}

Scene make_scene(SceneKind kind, cv::Size size, std::uint64_t seed) {
  check_size(size);
  switch (kind) {
    case SceneKind::Translation:
      return make_translation(size, cv::Point2f(kTranslation), seed);
    case SceneKind::Rotation:
      return make_rotation(size, seed);
    case SceneKind::Zoom:
      return make_zoom(size, seed);
    case SceneKind::NonRigid:
      return make_nonrigid(size, seed);
    case SceneKind::MovingObject:
      return make_moving_object(size, seed);
  }
  throw Error("unknown scene kind " + std::to_string(static_cast<int>(kind)));
}

const char* to_string(SceneKind kind) {
  switch (kind) {
    case SceneKind::Translation:
      return "translation";
    case SceneKind::Rotation:
      return "rotation";
    case SceneKind::Zoom:
      return "zoom";
    case SceneKind::NonRigid:
      return "nonrigid";
    case SceneKind::MovingObject:
      return "moving_object";
  }
  throw Error("unknown scene kind " + std::to_string(static_cast<int>(kind)));
}

}  // namespace roiflow::eval
