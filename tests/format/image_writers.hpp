// Test images written with libpng / libjpeg's encoders (the reader under test
// only decodes), so each test knows the pixels a file holds.
#pragma once

#include <cstdint>
#include <vector>

namespace sogmm_test {

/// PNG of `width` x `height` with libpng's colour type and bit depth; `rows`
/// holds the raw samples (16-bit samples big-endian, as PNG stores them).
/// `interlace` selects Adam7. A palette image gets `palette` (RGB triples)
/// and, if not empty, a tRNS chunk of `alpha`.
std::vector<std::uint8_t> write_png(int width, int height, int color_type, int bit_depth,
                                    const std::vector<std::uint8_t>& samples, bool interlace = false,
                                    const std::vector<std::uint8_t>& palette = {},
                                    const std::vector<std::uint8_t>& alpha = {});

/// Baseline JPEG at quality 100 of `components` 1 (gray) or 3 (RGB).
std::vector<std::uint8_t> write_jpeg(int width, int height, int components, const std::vector<std::uint8_t>& pixels,
                                     bool progressive = false);

}  // namespace sogmm_test
