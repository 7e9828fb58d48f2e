// Streaming decoder of one array: zstd frames (or raw bytes) -> byte-stream
// join and transpose -> canonical bytes, without intermediate copies.
#include "decode.hpp"

// zstd_contexts.hpp defines ZSTD_STATIC_LINKING_ONLY, which also gives
// ZSTD_d_stableOutBuffer: decode into our buffer, no window copy.
#include "zstd_contexts.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "container.hpp"

namespace sogmm::format::detail {
namespace {

constexpr std::size_t kChunk = 64 << 10;  // bytes read from a file at a time

[[noreturn]] void bad(const std::string& detail) { fail(ErrorCode::Format, "decompression_failed", detail); }

// The stored bytes of one array, consumed front to back: the whole range when
// the source is in memory, else a chunk at a time.
class StoredBytes {
 public:
  StoredBytes(const Source& src, std::uint64_t offset, std::uint64_t length)
      : src_(src), next_(offset), end_(offset + length) {
    if (const std::uint8_t* all = src.view(offset, static_cast<std::size_t>(length))) {
      data_ = all;
      avail_ = static_cast<std::size_t>(length);
      next_ = end_;
    } else {
      buffer_.resize(static_cast<std::size_t>(std::min<std::uint64_t>(length, kChunk)));
      data_ = buffer_.data();  // never null when there is something to read
    }
  }
  /// Makes at least min(want, left()) bytes available at data(); returns how many are.
  std::size_t fill(std::size_t want) {
    if (avail_ >= want || next_ == end_) return avail_;
    std::memmove(buffer_.data(), data_, avail_);
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(buffer_.size() - avail_, end_ - next_));
    src_.read(next_, buffer_.data() + avail_, n);
    next_ += n;
    avail_ += n;
    data_ = buffer_.data();
    return avail_;
  }
  const std::uint8_t* data() const { return data_; }
  std::size_t available() const { return avail_; }
  void consume(std::size_t n) {
    data_ += n;
    avail_ -= n;
  }
  /// Bytes not yet consumed.
  std::uint64_t left() const { return avail_ + (end_ - next_); }

 private:
  const Source& src_;
  std::uint64_t next_, end_;  // file range not yet read
  std::vector<std::uint8_t> buffer_;
  const std::uint8_t* data_ = nullptr;
  std::size_t avail_ = 0;
};

// Writes filtered bytes, in stored order, to their canonical positions.
// Stored order: BYTE_STREAM_SPLIT gives byte k of element i at k * n + i,
// else element after element; COLUMN_MAJOR orders the elements as column c
// of component r at c * M + r, else component after component.
class Scatter {
 public:
  Scatter(const Shape& s, const Encoding& e, std::uint8_t* out)
      : out_(out), total_(s.bytes()), rows_(s.rows), cols_(s.cols), width_(s.width), n_(s.rows * s.cols),
        split_(e.filter != kFilterNone), column_major_(e.order == kOrderColumnMajor) {}

  bool identity() const { return !split_ && !column_major_; }
  std::uint64_t written() const { return written_; }

  /// Records n bytes that the caller wrote itself at out + written() (identity layout only).
  void placed(std::size_t n) {
    if (n > total_ - written_) bad("data decodes to more than the declared " + std::to_string(total_) + " bytes");
    written_ += n;
  }

  void put(const std::uint8_t* p, std::size_t n) {
    const std::uint64_t at = written_;
    placed(n);
    if (identity()) {
      if (n > 0) std::memcpy(out_ + at, p, n);
      return;
    }
    while (n > 0) {
      const std::uint64_t element = column_major_ ? row_ * cols_ + col_ : index_;
      if (split_) {
        // A run of byte k of successive elements, up to the end of the column or stream.
        const std::uint64_t run = std::min<std::uint64_t>(n, column_major_ ? rows_ - row_ : n_ - index_);
        const std::uint64_t stride = column_major_ ? cols_ * width_ : width_;
        std::uint8_t* dst = out_ + element * width_ + byte_;
        for (std::uint64_t t = 0; t < run; ++t) dst[t * stride] = p[t];
        advance_elements(run);
        if (index_ == n_) {
          index_ = row_ = col_ = 0;
          ++byte_;
        }
        p += run;
        n -= static_cast<std::size_t>(run);
      } else {
        // Whole elements in column-major order: the rest of the current one.
        const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(n, width_ - byte_));
        std::memcpy(out_ + element * width_ + byte_, p, take);
        byte_ += take;
        if (byte_ == width_) {
          byte_ = 0;
          advance_elements(1);
        }
        p += take;
        n -= take;
      }
    }
  }

 private:
  void advance_elements(std::uint64_t count) {
    index_ += count;
    if (column_major_) {
      row_ += count;  // runs never cross a column
      if (row_ == rows_) {
        row_ = 0;
        ++col_;
      }
    }
  }

  std::uint8_t* out_;
  std::uint64_t total_, rows_, cols_, width_, n_;
  bool split_, column_major_;
  std::uint64_t written_ = 0;
  std::uint64_t index_ = 0, row_ = 0, col_ = 0, byte_ = 0;  // position of the next stored byte
};

std::string zstd_error(int frame, std::size_t code) {
  return "frame " + std::to_string(frame) + ": " + ZSTD_getErrorName(code) +
         (ZSTD_getErrorCode(code) == ZSTD_error_dstSize_tooSmall ? " (decodes to more than declared)" : "");
}

// A frame's output against its declared content size (zstd checks this
// itself; the format does not rely on that).
void check_content_size(int frame, std::uint64_t got, std::uint64_t declared) {
  if (got != declared) {
    bad("frame " + std::to_string(frame) + " decodes to " + std::to_string(got) + " bytes, its header declares " +
        std::to_string(declared));
  }
}

// Feeds one frame's input to zstd until the frame ends; `flush` sees the
// output after every step (a streamed frame empties it there).
template <typename Flush>
void decode_frame(ZSTD_DCtx* dctx, StoredBytes& in, ZSTD_outBuffer& ob, int frame, Flush&& flush) {
  std::size_t hint = 1;
  while (hint != 0) {
    if (in.available() == 0 && in.fill(kChunk) == 0) bad("frame " + std::to_string(frame) + " is truncated");
    ZSTD_inBuffer ib{in.data(), in.available(), 0};
    const std::size_t before = ob.pos;
    hint = ZSTD_decompressStream(dctx, &ob, &ib);
    throw_if_out_of_memory(hint);
    if (ZSTD_isError(hint)) bad(zstd_error(frame, hint));
    in.consume(ib.pos);
    const bool progress = ib.pos > 0 || ob.pos > before;
    flush(ob);
    if (hint != 0 && !progress) bad("frame " + std::to_string(frame) + " decodes to more than declared");
  }
}

// The structure of the zstd frames that section 5.4 has every reader check
// itself, before decoding: zstd versions differ on some of it (1.5.7
// rejects set reserved bits of Symbol_Compression_Modes that 1.5.4 ignores,
// blocks larger than the window that 1.5.4 decodes, and reads a 2-byte
// Number_of_Sequences of 0 differently), and a file must have one verdict.
// RFC 8878 names the fields.
class FrameWalker {
 public:
  explicit FrameWalker(StoredBytes& in) : in_(in) {}

  void walk() {
    for (frame_ = 0; in_.left() > 0; ++frame_) {
      if (le(4) != ZSTD_MAGICNUMBER) bad(where() + "does not start with the zstd magic number");
      // Bit 4 (Unused_Bit) is not read: RFC 8878 says a decoder ignores it.
      const std::uint8_t fhd = byte();
      if (fhd & 0x08) bad(where() + "reserved bit of the frame header descriptor is set");
      const bool single = (fhd >> 5) & 1;
      const int fcs_flag = fhd >> 6;
      if (fcs_flag == 0 && !single) bad(where() + "does not declare its content size");
      std::uint64_t window = 0;
      if (!single) {
        const std::uint8_t wd = byte();  // Exponent (bits 3-7), Mantissa (bits 0-2)
        const std::uint64_t base = std::uint64_t{1} << (10 + (wd >> 3));
        window = base + base / 8 * (wd & 7);
      }
      static constexpr int kDictionaryIdBytes[4] = {0, 1, 2, 4}, kContentSizeBytes[4] = {1, 2, 4, 8};
      skip(kDictionaryIdBytes[fhd & 3]);
      const std::uint64_t content_size = le(kContentSizeBytes[fcs_flag]) + (fcs_flag == 1 ? 256 : 0);
      if (single) window = content_size;
      if (window > kMaxWindow) bad(where() + "window of " + std::to_string(window) + " bytes, above 2^31");
      block_max_ = std::min<std::uint64_t>(window, 128u << 10);  // Block_Maximum_Size
      for (bool last = false; !last;) {
        const std::uint32_t h = static_cast<std::uint32_t>(le(3));
        last = h & 1;
        const std::uint32_t type = (h >> 1) & 3, size = h >> 3;
        if (type == 3) bad(where() + "block of the reserved type 3");
        if (size > block_max_) bad(where() + "block of " + std::to_string(size) + " bytes, above " + max_text());
        if (type == 2) {
          compressed_block(size);
        } else {
          skip(type == 1 ? 1 : size);
        }
      }
      if ((fhd >> 2) & 1) skip(4);  // content checksum, verified when decoding
    }
  }

 private:
  // ZSTD_WINDOWLOG_MAX of a 64-bit libzstd: larger windows are refused there.
  static constexpr std::uint64_t kMaxWindow = std::uint64_t{1} << 31;

  std::string max_text() const {
    return "the frame's Block_Maximum_Size of " + std::to_string(block_max_) + " bytes";
  }

  void compressed_block(std::uint32_t size) {
    const std::uint8_t b0 = byte();
    const int type = b0 & 3, format = (b0 >> 2) & 3;
    std::uint64_t header = 0, content = 0, regenerated = 0;
    if (type < 2) {  // raw or RLE literals: Regenerated_Size only
      header = format == 1 ? 2 : format == 3 ? 3 : 1;
      const std::uint64_t rest = le(static_cast<int>(header) - 1);
      regenerated = header == 1 ? b0 >> 3 : (b0 >> 4) + (rest << 4);
      content = type == 0 ? regenerated : 1;
    } else {  // compressed or treeless: Regenerated_Size and Compressed_Size
      header = format < 2 ? 3 : format == 2 ? 4 : 5;
      const std::uint64_t v = (b0 + (le(static_cast<int>(header) - 1) << 8)) >> 4;
      const int bits = header == 3 ? 10 : header == 4 ? 14 : 18;
      content = v >> bits;
      regenerated = v & ((std::uint64_t{1} << bits) - 1);
    }
    if (regenerated > block_max_) {
      bad(where() + "literals regenerate " + std::to_string(regenerated) + " bytes, above " + max_text());
    }
    if (header + content >= size) bad(where() + "literals leave no room for the sequences section");
    skip(content);
    std::uint64_t left = size - header - content;
    const std::uint8_t n0 = byte();
    --left;
    const std::uint64_t count_bytes = n0 < 128 ? 0 : n0 < 255 ? 1 : 2;
    if (left < count_bytes) bad(where() + "sequences section header beyond the block");
    // Only the 2-byte form 80 00 can also spell 0; the 3-byte form is at least 0x7F00.
    if (n0 == 128 && byte() == 0) bad(where() + "Number_of_Sequences of 0 in its 2-byte form");
    if (n0 == 0) {
      if (left != 0) bad(where() + "bytes after an empty sequences section");
      return;
    }
    if (left < count_bytes + 1) bad(where() + "sequences section header beyond the block");
    skip(n0 == 128 ? 0 : count_bytes);
    if (byte() & 3) bad(where() + "reserved bits of Symbol_Compression_Modes are set");
    skip(left - count_bytes - 1);
  }

  std::string where() const { return "frame " + std::to_string(frame_) + ": "; }

  std::uint8_t byte() {
    if (in_.available() == 0 && in_.fill(1) == 0) bad(where() + "truncated");
    const std::uint8_t v = in_.data()[0];
    in_.consume(1);
    return v;
  }
  std::uint64_t le(int n) {
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(byte()) << (8 * i);
    return v;
  }
  void skip(std::uint64_t n) {
    while (n > 0) {
      std::size_t a = in_.available();
      if (a == 0 && (a = in_.fill(kChunk)) == 0) bad(where() + "truncated");
      const std::size_t t = static_cast<std::size_t>(std::min<std::uint64_t>(a, n));
      in_.consume(t);
      n -= t;
    }
  }

  StoredBytes& in_;
  int frame_ = 0;
  std::uint64_t block_max_ = 0;
};

void decode_zstd(StoredBytes& in, Scatter& scatter, std::uint8_t* out, std::uint64_t expected) {
  const DCtx dctx = new_dctx();
  // Frames are decoded either into a buffer that holds the whole frame and
  // serves as its window (stable output), or, when the layout needs staging
  // and the frame's window is smaller than its content, streamed through a
  // small chunk (zstd then keeps only the window). Either way a frame costs
  // at most its content, which is checked against what is left first, so the
  // largest window a frame may ask for is accepted.
  ZSTD_DCtx_setParameter(dctx.get(), ZSTD_d_windowLogMax, ZSTD_WINDOWLOG_MAX);
  // One frame's content when staged; not zero-filled, so only the pages a
  // frame writes become resident.
  std::unique_ptr<std::uint8_t[]> staging;
  std::size_t staging_size = 0;
  std::vector<std::uint8_t> chunk;  // output of streamed frames
  for (int frame = 0; in.left() > 0; ++frame) {
    in.fill(ZSTD_FRAMEHEADERSIZE_MAX);
    if (in.available() < 4 || load_le<std::uint32_t>(in.data()) != ZSTD_MAGICNUMBER) {
      bad("frame " + std::to_string(frame) + " does not start with the zstd magic number");
    }
    ZSTD_frameHeader fh{};
    const std::size_t need = ZSTD_getFrameHeader(&fh, in.data(), in.available());
    if (ZSTD_isError(need)) bad(zstd_error(frame, need));
    if (need > 0) bad("frame " + std::to_string(frame) + ": truncated frame header");
    // Section 5.4: every frame declares its content size and uses no
    // dictionary, so its output is known before it is decoded, whatever the
    // zstd version. Checked before anything is allocated: a frame may not
    // promise more than is left.
    if (fh.frameContentSize == ZSTD_CONTENTSIZE_UNKNOWN) {
      bad("frame " + std::to_string(frame) + " does not declare its content size");
    }
    if (fh.dictID != 0) bad("frame " + std::to_string(frame) + " needs a dictionary");
    const std::uint64_t left = expected - scatter.written();
    if (fh.frameContentSize > left) {
      bad("frame " + std::to_string(frame) + " declares " + std::to_string(fh.frameContentSize) +
          " bytes, more than the " + std::to_string(left) + " left of the declared length");
    }
    const std::size_t cap = static_cast<std::size_t>(fh.frameContentSize);
    const std::uint64_t before = scatter.written();
    const bool streamed = !scatter.identity() && fh.windowSize < cap;
    ZSTD_DCtx_reset(dctx.get(), ZSTD_reset_session_only);  // a new output buffer per frame
    ZSTD_DCtx_setParameter(dctx.get(), ZSTD_d_stableOutBuffer, streamed ? 0 : 1);
    if (streamed) {
      chunk.resize(ZSTD_DStreamOutSize());
      ZSTD_outBuffer ob{chunk.data(), chunk.size(), 0};
      decode_frame(dctx.get(), in, ob, frame, [&](ZSTD_outBuffer& o) {
        scatter.put(chunk.data(), o.pos);
        o.pos = 0;
      });
      check_content_size(frame, scatter.written() - before, cap);
      continue;
    }
    std::uint8_t* dst = out + scatter.written();
    if (!scatter.identity()) {
      if (staging_size < cap) {
        staging.reset();
        staging.reset(new std::uint8_t[cap]);
        staging_size = cap;
      }
      dst = staging.get();
    }
    ZSTD_outBuffer ob{dst, cap, 0};
    decode_frame(dctx.get(), in, ob, frame, [](ZSTD_outBuffer&) {});
    check_content_size(frame, ob.pos, cap);
    if (scatter.identity()) {
      scatter.placed(ob.pos);
    } else {
      scatter.put(dst, ob.pos);
    }
  }
}

}  // namespace

void decode_array(const Source& src, std::uint64_t offset, std::uint64_t stored_length, const Shape& shape,
                  const Encoding& e, std::uint8_t* out) {
  const std::uint64_t expected = shape.bytes();
  StoredBytes in(src, offset, stored_length);
  Scatter scatter(shape, e, out);
  if (e.codec == kCodecZstd) {
    StoredBytes structure(src, offset, stored_length);
    FrameWalker(structure).walk();
    decode_zstd(in, scatter, out, expected);
  } else {
    while (in.left() > 0) {
      const std::size_t n = in.fill(kChunk);
      scatter.put(in.data(), n);
      in.consume(n);
    }
  }
  if (scatter.written() != expected) {
    bad("data decodes to " + std::to_string(scatter.written()) + " bytes, " + std::to_string(expected) + " declared");
  }
}

}  // namespace sogmm::format::detail
