// The rule for the free-form metadata strings of a model (producer name and
// version, key/value keys and values; spec/format.md section 4.4): valid
// UTF-8 without U+0000. One definition for the file reader and writer, the
// JSON dump and the C API's setters. Header-only, so that the C API can use
// it whether or not it is built with the format library.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>

namespace sogmm {

namespace metadata_string_detail {

// Length of the well-formed UTF-8 sequence at p[i] (RFC 3629; table 3-7 of
// the Unicode standard), or 0.
inline std::size_t sequence_length(const unsigned char* p, std::size_t i, std::size_t n) {
  const unsigned char b = p[i];
  if (b < 0x80) return 1;
  std::size_t len = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
  if (b >= 0xC2 && b <= 0xDF) {
    len = 2;
  } else if (b >= 0xE0 && b <= 0xEF) {
    len = 3;
    if (b == 0xE0) lo = 0xA0;  // no overlong forms
    if (b == 0xED) hi = 0x9F;  // no surrogates U+D800..U+DFFF
  } else if (b >= 0xF0 && b <= 0xF4) {
    len = 4;
    if (b == 0xF0) lo = 0x90;  // no overlong forms
    if (b == 0xF4) hi = 0x8F;  // nothing above U+10FFFF
  } else {
    return 0;  // continuation byte, overlong lead (C0, C1) or F5..FF
  }
  if (n - i < len || p[i + 1] < lo || p[i + 1] > hi) return 0;
  for (std::size_t k = 2; k < len; ++k) {
    if (p[i + k] < 0x80 || p[i + k] > 0xBF) return 0;
  }
  return len;
}

}  // namespace metadata_string_detail

/// Empty when the n bytes at `s` are valid UTF-8 (no overlong forms, no
/// surrogates, nothing above U+10FFFF) without a NUL byte; otherwise what is
/// wrong and at which byte, e.g. "byte 3 (0xff) is not valid UTF-8".
inline std::string metadata_string_problem(const char* s, std::size_t n) {
  const auto* p = reinterpret_cast<const unsigned char*>(s);
  for (std::size_t i = 0; i < n;) {
    if (p[i] == 0) return "byte " + std::to_string(i) + " is NUL (U+0000)";
    const std::size_t len = metadata_string_detail::sequence_length(p, i, n);
    if (len == 0) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "byte %zu (0x%02x) is not valid UTF-8", i, p[i]);
      return buf;
    }
    i += len;
  }
  return {};
}

inline std::string metadata_string_problem(const std::string& s) { return metadata_string_problem(s.data(), s.size()); }

/// `s` made to follow the rule: each byte that does not (a NUL, or a byte of
/// no valid UTF-8 sequence) becomes U+FFFD. For text from outside that is to
/// become metadata, such as file names, which POSIX does not require to be UTF-8.
inline std::string to_metadata_string(const std::string& s) {
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t len = p[i] == 0 ? 0 : metadata_string_detail::sequence_length(p, i, s.size());
    if (len == 0) {
      out += "\xef\xbf\xbd";
      ++i;
    } else {
      out.append(s, i, len);
      i += len;
    }
  }
  return out;
}

}  // namespace sogmm
