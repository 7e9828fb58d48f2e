// Fuzz target: the frame reader (sogmm_frame_decode, C API) on arbitrary
// bytes, as a depth PNG and as a colour PNG/JPEG next to a fixed valid depth
// image. Any input must end in SOGMM_OK with a consistent frame or in a
// documented status (FORMAT, INVALID_DATA, LIMIT), never a crash, a leak, an
// escaped longjmp or an unbounded allocation (the pixel cap is 2^26).
#include <cstdint>
#include <cstring>

#include "fuzz_util.hpp"
#include "sogmm/sogmm.h"

namespace {

// A valid 1 x 1 16-bit gray PNG (depth 0), for the colour half.
const std::uint8_t kDepth1x1[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
    0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x10, 0x00, 0x00, 0x00, 0x00, 0x6a, 0xee, 0x47, 0x16, 0x00, 0x00, 0x00,
    0x0b, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x60, 0x60, 0x00, 0x00, 0x00, 0x03, 0x00, 0x01, 0xb8, 0xad,
    0x3a, 0x63, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

bool documented(sogmm_status s) {
  return s == SOGMM_E_FORMAT || s == SOGMM_E_INVALID_DATA || s == SOGMM_E_LIMIT;
}

void check_frame(sogmm_status s, sogmm_frame* f) {
  if (s != SOGMM_OK) {
    FUZZ_CHECK(documented(s) && f == nullptr && sogmm_last_error()[0] != '\0');
    return;
  }
  const std::uint64_t w = sogmm_frame_width(f), h = sogmm_frame_height(f);
  FUZZ_CHECK(w >= 1 && h >= 1 && w * h <= (std::uint64_t{1} << 26));
  const int32_t format = sogmm_frame_color_format(f);
  FUZZ_CHECK(format == 0 || format == SOGMM_COLOR_GRAY8 || format == SOGMM_COLOR_RGB8);
  // Touch the first and last pixel: the buffers have the advertised size.
  const uint16_t* d = sogmm_frame_depth(f);
  volatile std::uint32_t sum = d[0] + d[w * h - 1];
  if (format != 0) {
    const uint8_t* c = sogmm_frame_color(f);
    sum = sum + c[0] + c[(format == SOGMM_COLOR_RGB8 ? 3 : 1) * w * h - 1];
  }
  (void)sum;
  sogmm_frame_free(f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::uint8_t kNone = 0;
  const std::uint8_t* bytes = size > 0 ? data : &kNone;  // empty input: bytes, not a NULL argument
  // The status first, then the frame it set (argument order is unspecified).
  sogmm_frame* f = nullptr;
  const sogmm_status depth = sogmm_frame_decode(&f, bytes, size, nullptr, 0);
  check_frame(depth, f);
  f = nullptr;
  // A colour image that decodes but is not 1 x 1 differs in size from the depth.
  const sogmm_status color = sogmm_frame_decode(&f, kDepth1x1, sizeof kDepth1x1, bytes, size);
  check_frame(color, f);
  return 0;
}
