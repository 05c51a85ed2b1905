#include <gtest/gtest.h>

#include <atomic>
#include <optional>
#include <string>

#include "pipeline/mot_demo.hpp"
#include "test_util.hpp"

namespace {

using namespace roiflow;

class DemoCommand : public test::TempDirTest {};

TEST_F(DemoCommand, OneObjectOrSeveralOrNothingWhenCancelled) {
  pipeline::DemoOptions o;
  o.dir = path("one");
  o.frames = 12;
  const std::optional<std::string> one = pipeline::demo_command_text(o, 0, true);
  ASSERT_TRUE(one.has_value());
  EXPECT_NE(one->find("success AUC"), std::string::npos) << *one;
  o.dir = path("several");
  const std::optional<std::string> several = pipeline::demo_command_text(o, 2, true);
  ASSERT_TRUE(several.has_value());
  EXPECT_NE(several->find("MOTA"), std::string::npos) << *several;
  EXPECT_NE(several->find("12 frames"), std::string::npos) << *several;  // --frames given
  std::atomic<bool> stop{true};
  o.cancel = &stop;
  EXPECT_FALSE(pipeline::demo_command_text(o, 0, true).has_value());
  EXPECT_FALSE(pipeline::demo_command_text(o, 2, true).has_value());
}

}  // namespace
