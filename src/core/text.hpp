// Text for the places it is shown: numbers with fixed decimals (libfmt), sizes, lists, numbers
// as the user wrote them, values quoted for an error message, text made safe for HTML/SVG, CSV
// fields, and messages on one line.
//
//   std::string line = "EPE " + roiflow::fixed(0.12345, 3) + " px at " +
//                      roiflow::size_text({640, 480});          // "EPE 0.123 px at 640x480"
//   line += " (" + roiflow::joined({"a.csv", "b.svg"}) + ")";   // "(a.csv, b.svg)"
//   const std::string error = "bad number " + roiflow::quoted_excerpt("12x") + ", roi " +
//                             roiflow::number_text(0.5);        // "bad number '12x', roi 0.5"
//   const std::string svg = "<text>" + roiflow::escape_markup("a < b") + "</text>";
//   const std::string cell = roiflow::csv_field("a,b");     // "\"a,b\""
//   const std::string said = roiflow::one_line("bad\nframe\n");  // "bad frame"
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <opencv2/core/types.hpp>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace roiflow {

// A number with a fixed count of decimals, like printf's "%.*f": fixed(3.14159, 2) is "3.14".
inline std::string fixed(double value, int decimals) {
  return fmt::format("{:.{}f}", value, decimals);
}

// "640x480".
inline std::string size_text(cv::Size size) {
  return fmt::format("{}x{}", size.width, size.height);
}

// The fields of `text` between `sep` characters, as views into it: "a,,b" gives "a", "", "b";
// an empty text gives one empty field.
inline std::vector<std::string_view> split_view(std::string_view text, char sep) {
  std::vector<std::string_view> fields;
  for (std::size_t start = 0;;) {
    const std::size_t at = text.find(sep, start);
    fields.push_back(text.substr(start, at - start));
    if (at == std::string_view::npos) return fields;
    start = at + 1;
  }
}

// "a, b, c" (with the default separator).
inline std::string joined(const std::vector<std::string>& items, std::string_view sep = ", ") {
  std::string list;
  for (const std::string& item : items)
    list += (list.empty() ? "" : std::string(sep)) + item;
  return list;
}

// A CSV field: quoted (quotes doubled) when it holds a comma, a quote or a line break.
inline std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

// Text on one line: line breaks become spaces, trailing spaces go (OpenCV's messages span lines;
// the CLI's error is one line).
inline std::string one_line(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text.erase(text.find_last_not_of(' ') + 1);
}

// A number as error messages show it: the shortest stream form ("0.5", "1e-06", "nan"), so that
// the value the user gave reads back as they wrote it.
inline std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The length of the well-formed UTF-8 sequence of two to four bytes at the start of `s`, or 0.
inline std::size_t utf8_sequence(std::string_view s) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char lead = byte(0);
  const std::size_t n = lead >= 0xC2 && lead <= 0xDF   ? 2
                        : lead >= 0xE0 && lead <= 0xEF ? 3
                        : lead >= 0xF0 && lead <= 0xF4 ? 4
                                                       : 0;
  if (n == 0 || s.size() < n) return 0;
  for (std::size_t i = 1; i < n; ++i)
    if ((byte(i) & 0xC0) != 0x80) return 0;
  // (No overlong three- or four-byte forms, no surrogates, nothing above U+10FFFF.)
  if ((lead == 0xE0 && byte(1) < 0xA0) || (lead == 0xED && byte(1) > 0x9F) ||
      (lead == 0xF0 && byte(1) < 0x90) || (lead == 0xF4 && byte(1) > 0x8F))
    return 0;
  return n;
}

// A value quoted for an error message, cut to 40 characters: a binary file read as text must
// not produce a screenful. Bytes that are not text (control characters, NUL, bytes outside
// well-formed UTF-8) are shown as \xHH, so the message stays one printable line whole.
inline std::string quoted_excerpt(std::string_view text) {
  constexpr std::size_t kMax = 40;
  const std::string_view kept = text.substr(0, kMax);
  std::string shown(1, '\'');
  for (std::size_t i = 0; i < kept.size();) {
    const auto c = static_cast<unsigned char>(kept[i]);
    if (c >= 0x20 && c < 0x7F) {
      shown += kept[i++];
    } else if (const std::size_t n = c >= 0x80 ? utf8_sequence(kept.substr(i)) : 0; n > 0) {
      shown.append(kept.substr(i, n));
      i += n;
    } else {
      shown += fmt::format("\\x{:02X}", c);
      ++i;
    }
  }
  shown.append(text.size() > kMax ? "...'" : "'");
  return shown;
}

// Text for HTML or XML (SVG) content and attribute values: the five special characters as
// entities, control characters other than tab dropped (XML 1.0 does not allow them).
inline std::string escape_markup(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t') out += c;
    }
  }
  return out;
}

}  // namespace roiflow
