// Point tables in, result columns out (point_table.hpp).
#include "point_table.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <sstream>

#include "file_util.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"

namespace sogmm::tools {

namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

void require_point_count(std::size_t n, const std::string& path) {
  require(n > 0, ErrorCode::InvalidData, path + ": no point");
  require(n <= kMaxPoints, ErrorCode::Limit, path + ": more than " + std::to_string(kMaxPoints) + " points");
}

void require_finite(float v, const std::string& path, std::size_t row) {
  require(std::isfinite(v), ErrorCode::InvalidData, path + ": point " + std::to_string(row) + " is not finite");
}

// NumPy's .npy: magic, version, header length, a Python dict literal, data.
std::vector<float> read_npy(const std::string& path, const std::string& bytes) {
  const auto bad = [&](const std::string& why) { throw Error(ErrorCode::Format, path + ": not a NumPy array: " + why); };
  if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0) bad("no .npy magic");
  const int major = static_cast<unsigned char>(bytes[6]);
  if (major < 1 || major > 3) bad("format version " + std::to_string(major) + " (1-3 are read)");
  const std::size_t length_bytes = major == 1 ? 2 : 4;
  std::uint64_t header_len = 0;
  for (std::size_t i = 0; i < length_bytes; ++i)
    header_len |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes[8 + i])) << (8 * i);
  const std::size_t start = 8 + length_bytes;
  if (header_len > bytes.size() - start) bad("header longer than the file");
  if (header_len > 65536) bad("header of " + std::to_string(header_len) + " bytes (NumPy writes a few dozen)");
  const std::string header = bytes.substr(start, static_cast<std::size_t>(header_len));
  std::smatch m;
  if (!std::regex_search(header, m, std::regex(R"('descr'\s*:\s*'([<|=]?)(f4|f8)')")))
    bad("dtype is not little-endian float32 or float64 (header " + header + ")");
  const std::size_t item = m[2] == "f4" ? 4 : 8;
  if (!std::regex_search(header, m, std::regex(R"('fortran_order'\s*:\s*(True|False))"))) bad("no fortran_order");
  const bool column_major = m[1] == "True";
  if (!std::regex_search(header, m, std::regex(R"('shape'\s*:\s*\(\s*(\d{1,12})\s*,\s*(\d{1,12})\s*\))")))
    bad("shape is not (n, columns)");
  const std::uint64_t n = std::stoull(m[1]), cols = std::stoull(m[2]);
  require(cols >= 3, ErrorCode::InvalidData, path + ": " + std::to_string(cols) + " columns; need x, y, z");
  require_point_count(static_cast<std::size_t>(std::min<std::uint64_t>(n, kMaxPoints + 1)), path);
  const std::size_t data = start + static_cast<std::size_t>(header_len);
  if ((bytes.size() - data) / item / cols < n) bad("the data is shorter than its shape");
  std::vector<float> out(3 * static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t at = column_major ? k * static_cast<std::size_t>(n) + i : i * cols + k;
      const char* p = bytes.data() + data + at * item;
      float v;
      if (item == 4) {
        std::memcpy(&v, p, 4);
      } else {
        double d;
        std::memcpy(&d, p, 8);
        v = static_cast<float>(d);
      }
      require_finite(v, path, i);
      out[3 * i + k] = v;
    }
  return out;
}

std::vector<float> read_text(const std::string& path, const std::string& text) {
  std::vector<float> out;
  std::istringstream in(text);
  std::string line;
  std::size_t line_no = 0;
  bool first = true;
  while (std::getline(in, line)) {
    ++line_no;
    const std::size_t begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos || line[begin] == '#') continue;
    const char* p = line.c_str() + begin;
    const bool numeric = std::strchr("+-.0123456789", *p) != nullptr;
    if (first && !numeric) {  // a header line
      first = false;
      continue;
    }
    first = false;
    for (int k = 0; k < 3; ++k) {
      while (*p == ' ' || *p == '\t' || *p == ',') ++p;
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      require(end != p, ErrorCode::Format,
              path + ":" + std::to_string(line_no) + ": expected 3 numbers x, y, z (got \"" + line + "\")");
      require_finite(static_cast<float>(v), path, out.size() / 3);
      out.push_back(static_cast<float>(v));
      p = end;
    }
    require(out.size() / 3 <= kMaxPoints, ErrorCode::Limit,
            path + ": more than " + std::to_string(kMaxPoints) + " points");
  }
  require_point_count(out.size() / 3, path);
  return out;
}

std::string npy_bytes(const std::vector<Column>& columns, std::size_t n) {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" + std::to_string(n) + ", " +
                       std::to_string(columns.size()) + "), }";
  // Magic (6) + version (2) + length (2) + header + '\n', padded to 64 bytes.
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  out += static_cast<char>(header.size() & 0xff);
  out += static_cast<char>(header.size() >> 8);
  out += header;
  for (std::size_t i = 0; i < n; ++i)
    for (const Column& c : columns) out.append(reinterpret_cast<const char*>(&c.values[i]), sizeof(double));
  return out;
}

std::string csv_bytes(const std::vector<Column>& columns, std::size_t n) {
  std::string out;
  for (std::size_t k = 0; k < columns.size(); ++k) out += (k ? "," : "") + columns[k].name;
  out += '\n';
  char buf[32];
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < columns.size(); ++k) {
      std::snprintf(buf, sizeof buf, "%.17g", columns[k].values[i]);
      if (k) out += ',';
      out += buf;
    }
    out += '\n';
  }
  return out;
}

}  // namespace

std::vector<float> read_points(const std::string& path) {
  const std::string bytes = read_input_file(path, "points");
  return ends_with(path, ".npy") ? read_npy(path, bytes) : read_text(path, bytes);
}

void write_columns(const std::string& path, const std::vector<Column>& columns) {
  const std::size_t n = columns.empty() ? 0 : columns[0].values.size();
  const std::string bytes = ends_with(path, ".npy") ? npy_bytes(columns, n) : csv_bytes(columns, n);
  write_file_atomic(path, bytes.data(), bytes.size());
}

}  // namespace sogmm::tools
