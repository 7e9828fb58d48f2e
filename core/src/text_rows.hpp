// The line-by-line reader of the text values a file's keys carry (a map's
// frames, a delta's steps): one loop, so every such key reports a bad line the
// same way ("<what>, line N: why").
#pragma once

#include <cstddef>
#include <sstream>
#include <string>

#include "sogmm/error.hpp"

namespace sogmm {
namespace detail {

// Calls row(fields, bad) for each line of text, where fields streams the
// line's whitespace-separated tokens and bad(why) is the Format error to
// throw for that line.
template <typename Row>
void for_each_text_row(const std::string& text, const std::string& what, Row&& row) {
  std::istringstream in(text);
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto bad = [&](const std::string& why) {
      return Error(ErrorCode::Format, what + ", line " + std::to_string(line_no) + ": " + why);
    };
    std::istringstream fields(line);
    row(fields, bad);
  }
}

}  // namespace detail
}  // namespace sogmm
