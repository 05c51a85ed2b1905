#include "tracking/template_search.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "eval/synthetic.hpp"
#include "test_util.hpp"

namespace roiflow::tracking {
namespace {

using test::error_message;

cv::Mat texture(cv::Size size, std::uint64_t seed) {
  return eval::make_translation(size, {0, 0}, seed).frame0;
}

TEST(TemplateSearch, FindsAPatchWhereItWasCut) {
  const cv::Mat image = texture({320, 240}, 3);
  const cv::Rect where(181, 67, 40, 30);
  const TemplateMatch m =
      match_template(image, image(where).clone(), cv::Rect(0, 0, 320, 240), {{1.0}, 0});
  EXPECT_NEAR(m.box.x, where.x, 0.1);
  EXPECT_NEAR(m.box.y, where.y, 0.1);
  EXPECT_EQ(m.box.width, 40.f);
  EXPECT_GT(m.score, 0.99);
}

TEST(TemplateSearch, APriorPicksTheNearerOfTwoEqualMatches) {
  cv::Mat image = texture({320, 240}, 9);
  const cv::Mat patch = texture({30, 40}, 10);
  patch.copyTo(image(cv::Rect(40, 50, 30, 40)));
  patch.copyTo(image(cv::Rect(230, 170, 30, 40)));
  TemplateSearchParams p{{1.0}, 0};
  MatchPrior prior{{245.f, 190.f}, 100, 0.1};  // at the second copy's centre
  const TemplateMatch near_second =
      match_template(image, patch, cv::Rect(0, 0, 320, 240), p, prior);
  EXPECT_NEAR(near_second.box.x, 230, 0.5);
  EXPECT_NEAR(near_second.box.y, 170, 0.5);
  EXPECT_GT(near_second.score, 0.99);  // the NCC itself, not less the penalty
  EXPECT_NEAR(near_second.ranked, near_second.score, 1e-3);
  prior.centre = {55.f, 70.f};  // the first copy's centre
  const TemplateMatch near_first = match_template(image, patch, cv::Rect(0, 0, 320, 240), p, prior);
  EXPECT_NEAR(near_first.box.x, 40, 0.5);
  EXPECT_NEAR(near_first.box.y, 50, 0.5);
  // Coarse to fine honours the prior too.
  p.coarse_side = 12;
  const TemplateMatch coarse = match_template(image, patch, cv::Rect(0, 0, 320, 240), p, prior);
  EXPECT_NEAR(coarse.box.x, 40, 0.5);
  EXPECT_NEAR(coarse.box.y, 50, 0.5);
  prior.penalty = -1;
  EXPECT_NE(error_message([&] {
              match_template(image, patch, cv::Rect(0, 0, 320, 240), p, prior);
            }).find("prior"),
            std::string::npos);
}

TEST(TemplateSearch, CoarseToFineFindsWhatTheFullSearchFinds) {
  const cv::Mat image = texture({400, 300}, 4);
  const cv::Rect where(37, 201, 90, 70);
  const cv::Mat templ = image(where).clone();
  const TemplateMatch full = match_template(image, templ, cv::Rect(0, 0, 400, 300), {{1.0}, 0});
  const TemplateMatch coarse = match_template(image, templ, cv::Rect(0, 0, 400, 300), {{1.0}, 16});
  EXPECT_NEAR(coarse.box.x, full.box.x, 0.01);
  EXPECT_NEAR(coarse.box.y, full.box.y, 0.01);
  EXPECT_NEAR(coarse.score, full.score, 1e-6);
}

TEST(TemplateSearch, RecoversSubPixelPositionAndScale) {
  const cv::Mat image = texture({320, 240}, 5);
  // The image shifted by (0.4, -0.3) px: the template cut at (100, 80) sits at (100.4, 79.7).
  cv::Mat shifted;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 0.4, 0, 1, -0.3);
  cv::warpAffine(image, shifted, shift, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  const TemplateMatch m =
      match_template(shifted, image(cv::Rect(100, 80, 48, 40)).clone(), cv::Rect(60, 40, 140, 120));
  EXPECT_NEAR(m.box.x, 100.4, 0.15);
  EXPECT_NEAR(m.box.y, 79.7, 0.15);
  // The template shown 20 % larger than the image it is searched in: scale 1.2 wins.
  cv::Mat larger;
  cv::resize(image, larger, {}, 1.2, 1.2, cv::INTER_AREA);
  const TemplateMatch s =
      match_template(larger, image(cv::Rect(100, 80, 48, 40)).clone(),
                     cv::Rect(0, 0, larger.cols, larger.rows), {{0.9, 1.0, 1.1, 1.2, 1.3}, 24});
  EXPECT_EQ(s.scale, 1.2);
  EXPECT_NEAR(s.box.x, 120, 1.0);
  EXPECT_NEAR(s.box.y, 96, 1.0);
}

TEST(TemplateSearch, ARegionTooSmallForEveryScaleFindsNothing) {
  const cv::Mat image = texture({100, 100}, 6);
  const TemplateMatch m =
      match_template(image, image(cv::Rect(0, 0, 50, 50)).clone(), cv::Rect(80, 80, 100, 100));
  EXPECT_EQ(m.score, -1);
  EXPECT_TRUE(m.box.empty());
}

TEST(TemplateSearch, RejectsBadInput) {
  const cv::Mat image = texture({64, 64}, 7);
  const cv::Mat templ = image(cv::Rect(0, 0, 8, 8)).clone();
  EXPECT_NE(error_message([&] { match_template(cv::Mat(), templ, {}); }).find("empty"),
            std::string::npos);
  cv::Mat color;
  cv::cvtColor(image, color, cv::COLOR_GRAY2BGR);
  EXPECT_NE(error_message([&] { match_template(color, templ, {}); }).find("single-channel"),
            std::string::npos);
  cv::Mat as_float;
  templ.convertTo(as_float, CV_32F);
  EXPECT_NE(error_message([&] { match_template(image, as_float, {}); }).find("8UC1"),
            std::string::npos);
  EXPECT_NE(error_message([&] {
              match_template(image, templ, {}, {{1.0, -0.5}, 0});
            }).find("-0.5"),
            std::string::npos);
}

TEST(TemplateSearch, DirectNccEqualsOpenCvsMatchTemplate) {
  cv::Mat image(41, 57, CV_32F), templ(23, 30, CV_32F);
  cv::randu(image, 0.f, 1.f);
  cv::randu(templ, 0.f, 1.f);
  image(cv::Rect(0, 0, 40, 25)).setTo(0.25f);  // flat windows: OpenCV's rule gives 0 there
  image(cv::Rect(9, 5, 30, 23)) = 0.5f * image(cv::Rect(9, 5, 30, 23)) + templ;
  cv::Mat direct, reference;
  ccoeff_normed_direct(image, templ, direct);
  cv::matchTemplate(image, templ, reference, cv::TM_CCOEFF_NORMED);
  ASSERT_EQ(direct.size(), reference.size());
  EXPECT_LT(cv::norm(direct, reference, cv::NORM_INF), 1e-4);
  double best = 0;
  cv::Point at;
  cv::minMaxLoc(direct, nullptr, &best, nullptr, &at);
  EXPECT_EQ(at, cv::Point(9, 5));
  EXPECT_GT(best, 0.85);
  EXPECT_NE(error_message([&] { ccoeff_normed_direct(templ, image, direct); }).find("no larger"),
            std::string::npos);
}

// The tracker's searches: a few positions per row (groups of four span rows) and image heights
// that are not whole groups of the integral images' four rows.
TEST(TemplateSearch, DirectNccOnSmallWindowsEqualsOpenCvs) {
  cv::RNG rng(11);
  for (const cv::Size positions :
       {cv::Size(6, 6), cv::Size(5, 7), cv::Size(1, 3), cv::Size(9, 2)}) {
    for (const cv::Size templ_size : {cv::Size(39, 23), cv::Size(8, 5), cv::Size(17, 30)}) {
      cv::Mat image(templ_size.height + positions.height - 1,
                    templ_size.width + positions.width - 1, CV_32F);
      cv::Mat templ(templ_size, CV_32F);
      rng.fill(image, cv::RNG::UNIFORM, 0.f, 1.f);
      rng.fill(templ, cv::RNG::UNIFORM, 0.f, 1.f);
      cv::Mat direct, reference;
      ccoeff_normed_direct(image, templ, direct);
      cv::matchTemplate(image, templ, reference, cv::TM_CCOEFF_NORMED);
      ASSERT_EQ(direct.size(), positions);
      EXPECT_LT(cv::norm(direct, reference, cv::NORM_INF), 1e-4)
          << positions << " positions, template " << templ_size;
    }
  }
}

// A template prepared once matches as the template itself does, prior and all.
TEST(TemplateSearch, APreparedTemplateMatchesAsTheTemplate) {
  cv::Mat image, patch;
  texture({160, 120}, 5).convertTo(image, CV_32F, 1.0 / 255);
  image(cv::Rect(70, 40, 33, 21)).copyTo(patch);
  const DirectTemplate prepared(patch);
  for (const MatchPrior prior : {MatchPrior{}, MatchPrior{{60.f, 50.f}, 20, 0.2}}) {
    for (const cv::Rect search : {cv::Rect(60, 30, 50, 40), cv::Rect(66, 37, 40, 27),
                                  cv::Rect(150, 100, 40, 40), cv::Rect(0, 0, 20, 20)}) {
      const TemplateMatch a = match_template(image, patch, search, {{1.0}, 0}, prior);
      const TemplateMatch b = match_template(image, prepared, search, prior);
      EXPECT_EQ(a.score, b.score) << search;
      EXPECT_EQ(a.ranked, b.ranked) << search;
      EXPECT_EQ(a.box, b.box) << search;
    }
  }
  EXPECT_GT(match_template(image, prepared, cv::Rect(60, 30, 50, 40)).score, 0.99);
  EXPECT_NE(error_message([&] { DirectTemplate{cv::Mat(3, 3, CV_8U)}; }).find("float"),
            std::string::npos);
}

}  // namespace
}  // namespace roiflow::tracking
