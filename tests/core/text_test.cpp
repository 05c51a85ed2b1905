#include "core/text.hpp"

#include <gtest/gtest.h>

namespace {

using namespace roiflow;

TEST(Text, FixedDecimalsSizesAndLists) {
  EXPECT_EQ(fixed(3.14159, 2), "3.14");
  EXPECT_EQ(fixed(2.6, 0), "3");
  EXPECT_EQ(fixed(-0.04, 1), "-0.0");
  EXPECT_EQ(size_text({640, 480}), "640x480");
  EXPECT_EQ(joined({"a", "b", "c"}), "a, b, c");
  EXPECT_EQ(joined({"a", "b"}, ","), "a,b");
  EXPECT_EQ(joined({}), "");
}

TEST(Text, CsvFieldsAreQuotedOnlyWhenTheyMustBe) {
  EXPECT_EQ(csv_field("plain name"), "plain name");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(csv_field("cr\r"), "\"cr\r\"");
}

TEST(Text, OneLine) {
  EXPECT_EQ(one_line("OpenCV(4.6) error:\n> bad size\n"), "OpenCV(4.6) error: > bad size");
  EXPECT_EQ(one_line("a\r\nb"), "a  b");
  EXPECT_EQ(one_line("\n\n"), "");
  EXPECT_EQ(one_line("kept"), "kept");
}

TEST(Text, MessagesAndMarkup) {
  EXPECT_EQ(number_text(0.5), "0.5");
  EXPECT_EQ(number_text(1e-6), "1e-06");
  EXPECT_EQ(quoted_excerpt("12x"), "'12x'");
  EXPECT_EQ(quoted_excerpt(std::string(50, 'z')), "'" + std::string(40, 'z') + "...'");
  // Bytes of a binary file read as text: NUL and control characters escaped, the message whole.
  EXPECT_EQ(quoted_excerpt(std::string("PIEH\x05\0\0\0ab", 10)), "'PIEH\\x05\\x00\\x00\\x00ab'");
  EXPECT_EQ(quoted_excerpt("a\tb\nc\x7f"), "'a\\x09b\\x0Ac\\x7F'");
  // Well-formed UTF-8 is text; a lone continuation byte, a cut sequence, an overlong form are not.
  EXPECT_EQ(quoted_excerpt("caf\xc3\xa9 \xe2\x82\xac"), "'caf\xc3\xa9 \xe2\x82\xac'");
  EXPECT_EQ(quoted_excerpt("\x80x\xc3"), "'\\x80x\\xC3'");
  EXPECT_EQ(quoted_excerpt("\xe0\x80\x80"), "'\\xE0\\x80\\x80'");
  EXPECT_EQ(escape_markup("a < b & \"c\""), "a &lt; b &amp; &quot;c&quot;");
}

}  // namespace
