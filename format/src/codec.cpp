// Element order, byte-stream split and zstd framing, encoding side.
#include "codec.hpp"

#include <memory>
#include <string>

#include "zstd_contexts.hpp"

#include "container.hpp"

namespace sogmm::format::detail {
namespace {

// Component-major <-> column-major transpose of rows x cols elements of width w.
std::vector<std::uint8_t> transpose(const std::vector<std::uint8_t>& in, std::uint64_t rows, std::uint64_t cols,
                                    std::uint64_t w) {
  std::vector<std::uint8_t> out(in.size());
  for (std::uint64_t r = 0; r < rows; ++r) {
    for (std::uint64_t c = 0; c < cols; ++c) {
      std::memcpy(&out[(c * rows + r) * w], &in[(r * cols + c) * w], w);
    }
  }
  return out;
}

// Byte k of element i goes to position k * n + i.
std::vector<std::uint8_t> split_streams(const std::vector<std::uint8_t>& in, std::uint64_t w) {
  const std::uint64_t n = in.size() / w;
  std::vector<std::uint8_t> out(in.size());
  for (std::uint64_t i = 0; i < n; ++i) {
    for (std::uint64_t k = 0; k < w; ++k) out[k * n + i] = in[i * w + k];
  }
  return out;
}

void append_frame(std::vector<std::uint8_t>& out, ZSTD_CCtx* cctx, const std::uint8_t* src, std::size_t size) {
  const std::size_t pos = out.size();
  out.resize(pos + ZSTD_compressBound(size));
  const std::size_t n = ZSTD_compress2(cctx, out.data() + pos, out.size() - pos, src, size);
  throw_if_out_of_memory(n);
  if (ZSTD_isError(n)) throw Error(ErrorCode::Format, std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
  out.resize(pos + n);
}

}  // namespace

std::vector<std::uint8_t> encode_array(const std::vector<std::uint8_t>& canonical, const Shape& shape,
                                       const Encoding& e, int zstd_level, bool one_frame) {
  std::vector<std::uint8_t> bytes =
      e.order == kOrderColumnMajor ? transpose(canonical, shape.rows, shape.cols, shape.width) : canonical;
  if (e.filter != kFilterNone) bytes = split_streams(bytes, shape.width);
  if (e.codec == kCodecNone) return bytes;

  const CCtx cctx = new_cctx();
  if (zstd_level < 1) zstd_level = 1;
  if (zstd_level > ZSTD_maxCLevel()) zstd_level = ZSTD_maxCLevel();
  ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_compressionLevel, zstd_level);
  ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_checksumFlag, 0);  // the format has its own CRC
  ZSTD_CCtx_setParameter(cctx.get(), ZSTD_c_contentSizeFlag, 1);
  std::vector<std::uint8_t> out;
  const std::size_t streams = e.filter != kFilterNone && !one_frame ? shape.width : 1;
  const std::size_t stream_size = bytes.size() / streams;
  for (std::size_t k = 0; k < streams; ++k) append_frame(out, cctx.get(), bytes.data() + k * stream_size, stream_size);
  return out;
}

}  // namespace sogmm::format::detail
