// Helpers shared by the conformance tools: the category names of
// spec/format.md section 9 as the tools print them, and reading a file.
#pragma once

#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "sogmm/format.hpp"

namespace sogmm_conformance {

inline const char* category_of(sogmm::ErrorCode c) {
  switch (c) {
    case sogmm::ErrorCode::Format: return "format";
    case sogmm::ErrorCode::Limit: return "limit";
    case sogmm::ErrorCode::InvalidData: return "invalid_data";
    case sogmm::ErrorCode::Numeric: return "numeric";
    case sogmm::ErrorCode::Io: return "io";
    case sogmm::ErrorCode::InvalidArgument: return "invalid_argument";
    // Not a reader's category (a read cannot be cancelled); named so that
    // every code prints something meaningful and -Wswitch stays quiet.
    case sogmm::ErrorCode::Cancelled: return "cancelled";
  }
  return "?";
}

inline std::vector<std::uint8_t> slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace sogmm_conformance
