// Dense LK's contract without ground truth: bad input, parameters, presets, tiny images.
#include "flow/dense_lk.hpp"
#include "flow/lk_kernels.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/error.hpp"
#include "core/executor.hpp"
#include "lk_configurations.hpp"
#include "test_util.hpp"

namespace roiflow::flow {
namespace {

using test::error_message;

bool all_finite(const cv::Mat& m) {
  return cv::checkRange(m, true, nullptr, -1e30, 1e30);
}

// A smooth random texture (8-bit), enough for LK to have gradients everywhere.
cv::Mat texture(cv::Size size, std::uint64_t seed) {
  cv::Mat noise(size, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(), 1.5);
  return smooth;
}

TEST(DenseLkTest, RejectsEmptyFrames) {
  const cv::Mat frame(40, 30, CV_8UC1, cv::Scalar(7));
  EXPECT_THROW(dense_flow(cv::Mat(), frame, LkParams::paper()), Error);
  EXPECT_THROW(dense_flow(frame, cv::Mat(), LkParams::paper()), Error);
  EXPECT_THROW(dense_flow(cv::Mat(), cv::Mat(), LkParams::paper()), Error);
  EXPECT_THROW(dense_flow(Pyramid{}, Pyramid{}, LkParams::paper()), Error);
}

TEST(DenseLkTest, SizeMismatchNamesBothSizes) {
  const cv::Mat a(240, 320, CV_8UC1, cv::Scalar(1)), b(120, 160, CV_8UC1, cv::Scalar(1));
  const std::string msg = error_message([&] { dense_flow(a, b, LkParams::paper()); });
  EXPECT_NE(msg.find("320x240"), std::string::npos) << msg;
  EXPECT_NE(msg.find("160x120"), std::string::npos) << msg;
  EXPECT_THROW(dense_flow(build_pyramid(a, 3, 0.5), build_pyramid(b, 3, 0.5), LkParams::paper()),
               Error);
}

TEST(DenseLkTest, RejectsUnsupportedType) {
  const cv::Mat a(24, 32, CV_64FC1, cv::Scalar(0.5));
  const std::string msg = error_message([&] { dense_flow(a, a, LkParams::paper()); });
  EXPECT_NE(msg.find("64F"), std::string::npos) << msg;
}

TEST(DenseLkTest, RejectsPyramidWithTooFewLevels) {
  const cv::Mat frame0 = texture({160, 120}, 2), frame1 = texture({160, 120}, 3);
  const Pyramid p0 = build_pyramid(frame0, 2, 0.5), p1 = build_pyramid(frame1, 2, 0.5);
  LkParams params = LkParams::paper();  // 3 levels
  const std::string msg = error_message([&] { dense_flow(p0, p1, params); });
  EXPECT_NE(msg.find("2 levels"), std::string::npos) << msg;
  params.levels = 2;
  EXPECT_NO_THROW(dense_flow(p0, p1, params));
}

TEST(DenseLkTest, RejectsEveryParameterOutOfRange) {
  struct Case {
    const char* field;  // the parameter the message must name
    const char* value;  // and the value, as it prints
    void (*apply)(LkParams&);
  };
  const Case cases[] = {
      {"patch", "2", [](LkParams& p) { p.patch = 2; }},
      {"patch", "32", [](LkParams& p) { p.patch = 32; }},
      {"levels", "-1", [](LkParams& p) { p.levels = -1; }},
      {"levels", "7", [](LkParams& p) { p.levels = 7; }},
      {"iterations", "0", [](LkParams& p) { p.iterations = 0; }},
      {"iterations", "51", [](LkParams& p) { p.iterations = 51; }},
      {"finest iterations", "-1", [](LkParams& p) { p.finest_iterations = -1; }},
      {"finest iterations", "51", [](LkParams& p) { p.finest_iterations = 51; }},
      {"sigma", "-1", [](LkParams& p) { p.sigma = -1; }},
      {"sigma", "nan", [](LkParams& p) { p.sigma = std::numeric_limits<double>::quiet_NaN(); }},
      {"lambda", "0", [](LkParams& p) { p.lambda = 0; }},
      {"robust", "-0.1", [](LkParams& p) { p.robust_scale = -0.1; }},
      {"median", "4", [](LkParams& p) { p.level_median = 4; }},
      {"median", "7", [](LkParams& p) { p.final_median = 7; }},
      {"expected motion", "-1", [](LkParams& p) { p.expected_motion = -1; }},
      {"search radius", "25", [](LkParams& p) { p.search_radius = 25; }},
      {"fuse step", "33", [](LkParams& p) { p.fuse_step = 33; }},
      {"fuse far step", "-1", [](LkParams& p) { p.fuse_far_step = -1; }},
      {"fuse far finest level", "6", [](LkParams& p) { p.fuse_far_finest_level = 6; }},
      {"coarsest side", "11", [](LkParams& p) { p.coarsest_side = 11; }},
      {"fuse finest level", "6", [](LkParams& p) { p.fuse_finest_level = 6; }},
      {"finest level", "-1", [](LkParams& p) { p.finest_level = -1; }},
  };
  const cv::Mat frame(24, 32, CV_8UC1, cv::Scalar(9));
  for (const Case& c : cases) {
    LkParams params = LkParams::paper();
    c.apply(params);
    const std::string msg = error_message([&] { params.validate(); });
    EXPECT_NE(msg.find(c.field), std::string::npos) << msg;
    EXPECT_NE(msg.find(std::string("got ") + c.value), std::string::npos) << msg;
    // dense_flow validates before it looks at the frames.
    EXPECT_EQ(error_message([&] { dense_flow(frame, frame, params); }), msg);
    EXPECT_EQ(error_message([&] { dense_flow(cv::Mat(), cv::Mat(), params); }), msg);
  }
}

TEST(DenseLkTest, PresetsAndDerivativeNames) {
  const LkParams paper = LkParams::paper();
  EXPECT_EQ(paper.patch, 10);
  EXPECT_EQ(paper.levels, 3);
  EXPECT_EQ(paper.iterations, 3);
  EXPECT_EQ(paper.derivative, Derivative::HornSchunck);
  EXPECT_NO_THROW(paper.validate());
  EXPECT_NO_THROW(LkParams::accurate().validate());
  EXPECT_NO_THROW(LkParams{}.validate());
  const std::vector<std::string> names = LkParams::preset_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "paper"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "accurate"), names.end());
  for (const std::string& name : names)
    EXPECT_NO_THROW(LkParams::preset(name).validate()) << name;
  EXPECT_EQ(LkParams::preset("paper").patch, paper.patch);
  EXPECT_EQ(LkParams::preset("accurate").levels, LkParams::accurate().levels);
  const std::string msg = error_message([] { LkParams::preset("nope"); });
  EXPECT_NE(msg.find("nope"), std::string::npos) << msg;

  for (const Derivative d : {Derivative::HornSchunck, Derivative::Scharr, Derivative::Central})
    EXPECT_EQ(derivative_from_string(to_string(d)), d) << to_string(d);
  const std::string bad = error_message([] { derivative_from_string("sobel"); });
  EXPECT_NE(bad.find("sobel"), std::string::npos) << bad;
}

TEST(DenseLkTest, TinyImagesGiveFiniteFlowOfTheRightSize) {
  cv::RNG rng(3);
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(2, 2), cv::Size(1, 50), cv::Size(50, 1),
                              cv::Size(7, 5), cv::Size(13, 13), cv::Size(25, 24)}) {
    cv::Mat a(size, CV_8UC1), b(size, CV_8UC1);
    rng.fill(a, cv::RNG::UNIFORM, 0, 256);
    rng.fill(b, cv::RNG::UNIFORM, 0, 256);
    for (const test::NamedParams& c : test::lk_configurations()) {
      const FlowResult moved = dense_flow(a, b, c.params);
      ASSERT_EQ(moved.flow.size(), size) << c.name << " " << size;
      ASSERT_EQ(moved.flow.type(), CV_32FC2);
      ASSERT_EQ(moved.confidence.size(), size);
      EXPECT_TRUE(all_finite(moved.flow)) << c.name << " " << size;
      EXPECT_TRUE(all_finite(moved.confidence)) << c.name << " " << size;

      // Not exactly zero: the warp interpolates the last column and row with weight 1 on the
      // far sample, p00 + 1 * (p01 - p00), which can miss p01 by an ulp, and in a window of a
      // few pixels lambda barely damps it (measured up to 1.7e-7 px, at 2x2 with Scharr).
      const FlowResult still = dense_flow(a, a, c.params);
      ASSERT_EQ(still.flow.size(), size);
      EXPECT_LT(cv::norm(still.flow, cv::NORM_INF), 1e-6) << c.name << " " << size;
    }
  }
}

// The dispatch picks the widest kernels this CPU runs: NEON on arm64 (scripts/arm64.sh runs this
// under qemu), on x86-64 AVX-512 or AVX2 + FMA where the CPU has them, else SSE2.
TEST(LkKernelsTest, TheBestKindForThisCpu) {
  const detail::LkKernels& k = detail::lk_kernels();
#if defined(__aarch64__)
  EXPECT_STREQ(k.name, "neon");
  EXPECT_EQ(k.lanes, 4);
#elif defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq")) {
    EXPECT_STREQ(k.name, "avx512");
    EXPECT_EQ(k.lanes, 16);
  } else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    EXPECT_STREQ(k.name, "avx2");
    EXPECT_EQ(k.lanes, 8);
  } else {
    EXPECT_STREQ(k.name, "sse2");
    EXPECT_EQ(k.lanes, 4);
  }
#endif
  const detail::LkKernels* kinds[8];
  const int n = detail::available_lk_kernels(kinds, 8);
  ASSERT_GE(n, 1);
  EXPECT_EQ(kinds[0], &k);  // best first, and the baseline always last
  EXPECT_GE(kinds[n - 1]->lanes, 1);
}

// Every kind's x2 upsampling of a flow row (vector body, lane-by-lane tail, replicated last
// pixel, odd widths, both phases) against the rule written out pixel by pixel: bit for bit,
// since with fy in {0, 1/2} every step is exact or one rounding, fused or not.
TEST(LkKernelsTest, UpsampleRowOfEveryKindFollowsTheRule) {
  const detail::LkKernels* kinds[8];
  const int count = detail::available_lk_kernels(kinds, 8);
  cv::RNG rng(7);
  for (int n : {1, 2, 5, 17, 40, 83}) {
    std::vector<float> a(n), b(n);
    for (int j = 0; j < n; ++j) {
      a[j] = static_cast<float>(rng.uniform(-20.0, 20.0));
      b[j] = static_cast<float>(rng.uniform(-20.0, 20.0));
    }
    for (const float fy : {0.f, 0.5f}) {
      auto coarse = [&](int j) {
        j = std::min(j, n - 1);
        return 2.f * (a[j] + fy * (b[j] - a[j]));
      };
      for (int k0 = 0; k0 < std::min(n, 3); ++k0) {
        for (const bool between : {false, true}) {
          // The finer row ends at most one coarse pixel past the row (as a level's does).
          const int widest = 2 * (n - k0) + (between ? 0 : 1);
          for (int width : {1, 2, 3, widest - 1, widest}) {
            if (width < 1 || width > widest) continue;
            std::vector<float> want(width);
            for (int x = 0; x < width; ++x) {
              const int i = x / 2, j = k0 + i;
              const float mean = 0.5f * (coarse(j) + coarse(j + 1));
              const bool odd = (x & 1) != 0;
              want[x] = between ? (odd ? coarse(j + 1) : mean) : (odd ? mean : coarse(j));
            }
            for (int k = 0; k < count; ++k) {
              std::vector<float> temp(detail::upsample_temp_floats(n)), out(width + 64, -1.f);
              kinds[k]->upsample_row(a.data(), b.data(), fy, n, k0, between, width, temp.data(),
                                     out.data());
              for (int x = 0; x < width; ++x) {
                ASSERT_EQ(out[x], want[x])
                    << kinds[k]->name << " n " << n << " fy " << fy << " k0 " << k0 << " between "
                    << between << " width " << width << " x " << x;
              }
              EXPECT_EQ(out[width], -1.f) << kinds[k]->name << ": wrote past the row";
            }
          }
        }
      }
    }
  }
}

TEST(DenseLkTest, RegionOutsideTheFrameThrows) {
  const cv::Mat frame0 = texture({160, 120}, 2), frame1 = texture({160, 120}, 3);
  for (const cv::Rect region : {cv::Rect(160, 0, 10, 10), cv::Rect(-30, -30, 30, 30),
                                cv::Rect(500, 500, 20, 20), cv::Rect(0, 120, 160, 5)}) {
    FlowOptions options;
    options.region = region;
    EXPECT_THROW(dense_flow(frame0, frame1, LkParams::paper(), options), Error) << region;
  }
}

// Executors of two lanes that run the chunks of a region on two threads at once, or one after
// the other in either order: the two-chain schedule of the levels (iterate_levels_chained) gives
// the serial result bit for bit under each, and never waits forever.
class TwoLanes final : public Executor {
 public:
  enum class Order { Threads, InOrder, Reversed };
  explicit TwoLanes(Order order) : order_(order) {}
  void for_range(int begin, int end, int grain,
                 const std::function<void(int, int)>& body) const override {
    std::vector<std::pair<int, int>> chunks = test::chunks_of(begin, end, grain);
    if (order_ == Order::Reversed) std::reverse(chunks.begin(), chunks.end());
    if (order_ != Order::Threads) {
      for (const auto& [b, e] : chunks)
        body(b, e);
      return;
    }
    std::vector<std::thread> threads;
    for (const auto& [b, e] : chunks)
      threads.emplace_back([&body, b = b, e = e] { body(b, e); });
    for (std::thread& t : threads)
      t.join();
  }
  int concurrency() const override { return 2; }

 private:
  Order order_;
};

// A row pass steps along a row in chunks of a few thousand columns. A frame that repeats every
// 400 columns gets the same flow at the end of the first chunk as two periods to the left of it
// (a vector left unsolved, or a sum carried wrongly from one chunk to the next, would not).
TEST(DenseLkTest, RowsWiderThanOneChunkAreSolvedAlike) {
  cv::Mat a;
  cv::repeat(texture(cv::Size(400, 40), 5), 1, 11, a);
  cv::Mat b;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 0.7, 0, 1, -0.4);
  cv::warpAffine(a, b, shift, a.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  for (const test::NamedParams& c : test::lk_configurations()) {
    const FlowResult r = dense_flow(a, b, c.params);
    ASSERT_EQ(r.flow.size(), a.size()) << c.name;
    ASSERT_TRUE(all_finite(r.flow)) << c.name;
    const cv::Rect near_end(3900, 0, 400, a.rows);
    const double gap =
        cv::norm(r.flow(near_end), r.flow(near_end - cv::Point(800, 0)), cv::NORM_INF);
    EXPECT_LT(gap, 1e-3) << c.name;
  }
}

TEST(DenseLkTest, TwoChainsOfBandsGiveTheSerialResultBitForBit) {
  for (const cv::Size size : {cv::Size(192, 160), cv::Size(131, 203), cv::Size(64, 40)}) {
    const cv::Mat a = texture(size, 21);
    cv::Mat b;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0.05, 2.3, -0.04, 1, -1.6);
    cv::warpAffine(a, b, shift, size, cv::INTER_LINEAR, cv::BORDER_REFLECT);
    for (const test::NamedParams& c : test::lk_configurations()) {
      for (const cv::Rect region :
           {cv::Rect(), cv::Rect(10, 30, size.width / 2, size.height / 2)}) {
        FlowOptions options;
        options.region = region;
        const FlowResult serial = dense_flow(a, b, c.params, options);
        for (const auto order :
             {TwoLanes::Order::Threads, TwoLanes::Order::InOrder, TwoLanes::Order::Reversed}) {
          const TwoLanes lanes(order);
          DenseLK lk(c.params, &lanes);
          // The second call reuses the splits (once is enough for the one-thread orders).
          for (int call = 0; call < (order == TwoLanes::Order::Threads ? 2 : 1); ++call) {
            const FlowResult two = lk.calc(a, b, options);
            ASSERT_EQ(two.flow.size(), serial.flow.size());
            EXPECT_EQ(cv::norm(two.flow, serial.flow, cv::NORM_INF), 0.0)
                << c.name << " " << size << " " << region << " " << static_cast<int>(order);
            EXPECT_EQ(cv::norm(two.confidence, serial.confidence, cv::NORM_INF), 0.0)
                << c.name << " " << size << " " << region << " " << static_cast<int>(order);
          }
          if (order != TwoLanes::Order::InOrder) continue;
          // Without the confidence the chains give the same flow and leave none.
          FlowOptions off = options;
          off.confidence = false;
          const FlowResult bare = lk.calc(a, b, off);
          EXPECT_EQ(cv::norm(bare.flow, serial.flow, cv::NORM_INF), 0.0) << c.name << " " << size;
          EXPECT_TRUE(bare.confidence.empty());
        }
      }
    }
  }
}

}  // namespace
}  // namespace roiflow::flow
