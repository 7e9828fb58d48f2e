// PNG decoding with libpng for depth and colour frames. Fixed transforms
// only (no gamma, no background, no colour management), so the bytes depend
// on the file alone.
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "image_decoders.hpp"
#include "sogmm/error.hpp"

namespace sogmm::format::detail {
namespace {

// Reached from libpng's callbacks; plain C data.
struct PngContext {
  std::jmp_buf jump;
  char message[256];
  const unsigned char* data;
  std::size_t size;
  std::size_t pos;
};

extern "C" void png_on_error(png_structp png, png_const_charp msg) {
  auto* c = static_cast<PngContext*>(png_get_error_ptr(png));
  std::snprintf(c->message, sizeof c->message, "%s", msg);
  std::longjmp(c->jump, 1);
}

// Warnings (e.g. an ancillary chunk with a bad CRC, which libpng skips)
// change nothing in the pixels and are not printed.
extern "C" void png_on_warning(png_structp, png_const_charp) {}

extern "C" void png_on_read(png_structp png, png_bytep out, std::size_t n) {
  auto* c = static_cast<PngContext*>(png_get_io_ptr(png));
  if (n > c->size - c->pos) png_error(png, "truncated file (ends inside the image)");
  std::memcpy(out, c->data + c->pos, n);
  c->pos += n;
}

struct PngHeader {
  png_uint_32 width;
  png_uint_32 height;
  int bit_depth;
  int color_type;
};

// setjmp frames: C data only, so a longjmp skips no destructor.
bool read_header(png_structp png, png_infop info, PngContext* c, PngHeader* h) {
  if (setjmp(c->jump)) return false;
  png_read_info(png, info);
  h->width = png_get_image_width(png, info);
  h->height = png_get_image_height(png, info);
  h->bit_depth = png_get_bit_depth(png, info);
  h->color_type = png_get_color_type(png, info);
  return true;
}

// Applies the transforms to 1 or 3 channels of 8 bits (or 1 of 16 for
// depth), then reads every row; the row size libpng computes must be the one
// the caller allocated for.
bool read_pixels(png_structp png, png_infop info, PngContext* c, png_bytep* rows, std::size_t row_bytes) {
  if (setjmp(c->jump)) return false;
  const int type = png_get_color_type(png, info);
  if (type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (type == PNG_COLOR_TYPE_GRAY && png_get_bit_depth(png, info) < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (type & PNG_COLOR_MASK_ALPHA || png_get_valid(png, info, PNG_INFO_tRNS)) png_set_strip_alpha(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != row_bytes) png_error(png, "unexpected row size after the transforms");
  png_read_image(png, rows);
  png_read_end(png, nullptr);  // through IEND: a file cut after the pixels is truncated too
  return true;
}

// A libpng read struct with its info, released on every way out (also when
// the constructor throws: the handles are a member of their own).
class PngReader {
 public:
  PngReader(const void* data, std::size_t size, const std::string& name) : name_(name) {
    ctx_.data = static_cast<const unsigned char*>(data);
    ctx_.size = size;
    ctx_.pos = 0;
    ctx_.message[0] = '\0';
    h_.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &ctx_, png_on_error, png_on_warning);
    if (h_.png != nullptr) h_.info = png_create_info_struct(h_.png);
    require(h_.png != nullptr && h_.info != nullptr, ErrorCode::Io,
            name + ": cannot start the PNG decoder (out of memory)");
    png_set_read_fn(h_.png, &ctx_, png_on_read);
    // libpng keeps its default bound on each side (10^6 pixels); the pixel
    // count is checked below, before anything the size of the image exists.
    if (!read_header(h_.png, h_.info, &ctx_, &header_)) fail();
    check_frame_size(header_.width, header_.height, name);
  }

  const PngHeader& header() const { return header_; }

  /// Reads the pixels into `out` (row_bytes per row, height rows).
  void read(std::uint8_t* out, std::size_t row_bytes) {
    std::vector<png_bytep> rows(header_.height);
    for (std::size_t v = 0; v < rows.size(); ++v) rows[v] = out + v * row_bytes;
    if (!read_pixels(h_.png, h_.info, &ctx_, rows.data(), row_bytes)) fail();
  }

 private:
  struct Handles {
    png_structp png = nullptr;
    png_infop info = nullptr;
    Handles() = default;
    Handles(const Handles&) = delete;
    Handles& operator=(const Handles&) = delete;
    ~Handles() {
      if (png != nullptr) png_destroy_read_struct(&png, info != nullptr ? &info : nullptr, nullptr);
    }
  };

  [[noreturn]] void fail() const {
    throw Error(ErrorCode::Format, name_ + ": corrupt or truncated PNG (" + ctx_.message + ")");
  }

  std::string name_;
  PngContext ctx_{};
  Handles h_;
  PngHeader header_{};
};

const char* color_type_name(int type) {
  switch (type) {
    case PNG_COLOR_TYPE_GRAY: return "gray";
    case PNG_COLOR_TYPE_GRAY_ALPHA: return "gray with alpha";
    case PNG_COLOR_TYPE_PALETTE: return "palette";
    case PNG_COLOR_TYPE_RGB: return "RGB";
    default: return "RGBA";
  }
}

}  // namespace

DepthImage png_depth(const void* data, std::size_t size, const std::string& name) {
  PngReader reader(data, size, name);
  const PngHeader& h = reader.header();
  require(h.color_type == PNG_COLOR_TYPE_GRAY, ErrorCode::InvalidData,
          name + ": a depth image must have one channel (gray), this PNG is " + color_type_name(h.color_type));
  require(h.bit_depth == 16 || h.bit_depth == 8, ErrorCode::InvalidData,
          name + ": a depth image must be 16-bit (or 8-bit), this PNG has " + std::to_string(h.bit_depth) +
              " bits per pixel");
  DepthImage img;
  img.width = h.width;
  img.height = h.height;
  const std::size_t n = static_cast<std::size_t>(h.width) * h.height;
  img.pixels.resize(n);
  if (h.bit_depth == 16) {
    auto* bytes = reinterpret_cast<std::uint8_t*>(img.pixels.data());
    reader.read(bytes, static_cast<std::size_t>(h.width) * 2);
    // PNG samples are big-endian, whatever the machine.
    for (std::size_t i = 0; i < n; ++i)
      img.pixels[i] = static_cast<std::uint16_t>((bytes[2 * i] << 8) | bytes[2 * i + 1]);
  } else {
    std::vector<std::uint8_t> bytes(n);
    reader.read(bytes.data(), h.width);
    for (std::size_t i = 0; i < n; ++i) img.pixels[i] = bytes[i];
  }
  return img;
}

ColorImage png_color(const void* data, std::size_t size, const std::string& name) {
  PngReader reader(data, size, name);
  const PngHeader& h = reader.header();
  require(h.bit_depth <= 8, ErrorCode::InvalidData,
          name + ": a colour image must be 8-bit, this PNG has " + std::to_string(h.bit_depth) + " bits per channel");
  ColorImage img;
  img.width = h.width;
  img.height = h.height;
  img.channels = (h.color_type & PNG_COLOR_MASK_COLOR) ? 3 : 1;  // palette and RGB(A): 3; gray(+alpha): 1
  const std::size_t row = static_cast<std::size_t>(h.width) * static_cast<std::size_t>(img.channels);
  img.bytes.resize(row * h.height);
  reader.read(img.bytes.data(), row);
  return img;
}

bool is_png(const void* data, std::size_t size) {
  return size >= 8 && png_sig_cmp(static_cast<png_const_bytep>(data), 0, 8) == 0;
}

}  // namespace sogmm::format::detail
