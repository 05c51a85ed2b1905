#include "report/progress.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>

namespace {

using roiflow::report::Progress;

// A clock the test moves by hand, so that what is drawn, and when, is deterministic.
struct FakeClock {
  double now = 0;
  Progress::Clock function() {
    return [this] { return now; };
  }
};

TEST(Progress, DisabledPrintsNothing) {
  std::ostringstream out;
  FakeClock clock;
  {
    Progress progress(out, 100, false, clock.function());
    clock.now = 1;
    progress.update(50);
    progress.finish();
  }
  EXPECT_EQ(out.str(), "");
}

TEST(Progress, DrawsBarCountRateAndEta) {
  std::ostringstream out;
  FakeClock clock;
  Progress progress(out, 300, true, clock.function());
  clock.now = 1;
  progress.update(100);
  EXPECT_EQ(out.str(), "\r[######..............] 100/300 frames  100.0 fps  ETA 2s");
}

TEST(Progress, RedrawsAtMostTenTimesASecond) {
  std::ostringstream out;
  FakeClock clock;
  Progress progress(out, 1000, true, clock.function());
  clock.now = 1;
  progress.update(10);
  const std::string first = out.str();
  clock.now = 1.05;
  progress.update(11);
  EXPECT_EQ(out.str(), first) << "too soon to redraw";
  clock.now = 1.2;
  progress.update(12);
  EXPECT_NE(out.str(), first);
  EXPECT_NE(out.str().find("12/1000"), std::string::npos);
}

TEST(Progress, EtaInMinutesAndShorterLinesBlankTheRest) {
  std::ostringstream out;
  FakeClock clock;
  Progress progress(out, 10000, true, clock.function());
  clock.now = 1;
  progress.update(10);  // 10 fps, 9990 frames to go
  EXPECT_NE(out.str().find("ETA 16m39s"), std::string::npos) << out.str();
  const std::size_t first_length = out.str().size();
  out.str("");
  clock.now = 2;
  progress.update(9990);  // a much faster second
  const std::string second = out.str();
  EXPECT_NE(second.find("ETA 0s"), std::string::npos) << second;
  EXPECT_EQ(second.size(), first_length) << "padded to cover the longer previous line";
}

TEST(Progress, FinishPrintsTheFinalStateAndANewline) {
  std::ostringstream out;
  FakeClock clock;
  Progress progress(out, 300, true, clock.function());
  clock.now = 1;
  progress.update(100);
  clock.now = 3;
  progress.update(300);
  progress.finish();
  const std::string text = out.str();
  const std::string last = text.substr(text.rfind('\r'));
  EXPECT_EQ(last.substr(0, last.find_last_not_of(" \n") + 1),
            "\r[####################] 300/300 frames  100.0 fps  in 3s");
  EXPECT_EQ(text.back(), '\n');
  progress.finish();
  progress.update(301);
  EXPECT_EQ(out.str(), text) << "finish is idempotent and closes the line for good";
}

TEST(Progress, UnknownTotalShowsNoBarAndNoEta) {
  std::ostringstream out;
  FakeClock clock;
  Progress progress(out, 0, true, clock.function());
  clock.now = 2;
  progress.update(42);
  EXPECT_EQ(out.str(), "\r42 frames  21.0 fps");
  progress.finish();
  EXPECT_EQ(out.str(), "\r42 frames  21.0 fps\r42 frames  21.0 fps  in 2s\n");
}

TEST(Progress, DestructorEndsAStartedLineOnly) {
  std::ostringstream out;
  FakeClock clock;
  { Progress progress(out, 10, true, clock.function()); }
  EXPECT_EQ(out.str(), "") << "nothing was drawn, nothing to end";
  {
    Progress progress(out, 10, true, clock.function());
    clock.now = 1;
    progress.update(5);
  }
  EXPECT_EQ(out.str().back(), '\n');
}

}  // namespace
