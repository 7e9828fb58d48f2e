// JPEG decoding with libjpeg(-turbo) for colour frames. The settings that
// change pixels are fixed here (accurate integer IDCT, the library's
// default fancy upsampling and block smoothing, no scaling, no colour
// quantisation), so the bytes depend on the file and the libjpeg build only.
#include <cstdio>  // jpeglib.h needs FILE and size_t first

#include <jpeglib.h>

#include <csetjmp>
#include <vector>

#include "image_decoders.hpp"
#include "sogmm/error.hpp"

namespace sogmm::format::detail {
namespace {

// A progressive JPEG may carry any number of scans, each a full pass over
// the coefficients; real files have about 10 (libjpeg-turbo's tools also
// stop at 500).
constexpr int kMaxScans = 500;

// Reached from libjpeg's callbacks; plain C data. `err` comes first so the
// library's j_common_ptr->err points at the whole context.
struct JpegContext {
  jpeg_error_mgr err;
  jpeg_progress_mgr progress;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

extern "C" void jpeg_on_error(j_common_ptr cinfo) {
  auto* c = reinterpret_cast<JpegContext*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, c->message);
  std::longjmp(c->jump, 1);
}

// Level -1 is a warning about corrupt data (a truncated file, where libjpeg
// would fill the rest with gray): refused like an error. Trace messages
// (levels >= 0) are ignored, never printed.
extern "C" void jpeg_on_message(j_common_ptr cinfo, int level) {
  if (level < 0) jpeg_on_error(cinfo);
}

extern "C" void jpeg_on_progress(j_common_ptr cinfo) {
  auto* d = reinterpret_cast<j_decompress_ptr>(cinfo);
  if (d->input_scan_number > kMaxScans) {
    auto* c = reinterpret_cast<JpegContext*>(cinfo->err);
    std::snprintf(c->message, sizeof c->message, "more than %d scans", kMaxScans);
    std::longjmp(c->jump, 1);
  }
}

// setjmp frames: C data only, so a longjmp skips no destructor.
bool read_header(jpeg_decompress_struct* d, JpegContext* c, const unsigned char* data, std::size_t size) {
  if (setjmp(c->jump)) return false;
  jpeg_mem_src(d, data, static_cast<unsigned long>(size));
  jpeg_read_header(d, TRUE);
  return true;
}

bool read_pixels(jpeg_decompress_struct* d, JpegContext* c, J_COLOR_SPACE space, unsigned char* out,
                 std::size_t row_bytes) {
  if (setjmp(c->jump)) return false;
  d->out_color_space = space;
  d->dct_method = JDCT_ISLOW;
  d->do_fancy_upsampling = TRUE;
  d->do_block_smoothing = TRUE;
  d->quantize_colors = FALSE;
  d->scale_num = 1;
  d->scale_denom = 1;
  jpeg_start_decompress(d);
  if (static_cast<std::size_t>(d->output_width) * static_cast<std::size_t>(d->output_components) != row_bytes) {
    std::snprintf(c->message, sizeof c->message, "unexpected row size of the decoded image");
    std::longjmp(c->jump, 1);
  }
  while (d->output_scanline < d->output_height) {
    JSAMPROW row = out + static_cast<std::size_t>(d->output_scanline) * row_bytes;
    jpeg_read_scanlines(d, &row, 1);
  }
  jpeg_finish_decompress(d);
  return true;
}

// The decompressor and its context, released on every way out.
struct JpegReader {
  JpegContext ctx{};
  jpeg_decompress_struct d{};
  bool created = false;
  JpegReader() = default;
  JpegReader(const JpegReader&) = delete;
  JpegReader& operator=(const JpegReader&) = delete;
  ~JpegReader() {
    if (created) jpeg_destroy_decompress(&d);
  }
};

bool create(JpegReader* r) {
  if (setjmp(r->ctx.jump)) return false;
  jpeg_create_decompress(&r->d);
  r->created = true;
  return true;
}

}  // namespace

ColorImage jpeg_color(const void* data, std::size_t size, const std::string& name) {
  JpegReader r;
  r.d.err = jpeg_std_error(&r.ctx.err);
  r.ctx.err.error_exit = jpeg_on_error;
  r.ctx.err.emit_message = jpeg_on_message;
  auto fail = [&] { return Error(ErrorCode::Format, name + ": corrupt or truncated JPEG (" + r.ctx.message + ")"); };
  if (!create(&r)) throw fail();
  r.ctx.progress.progress_monitor = jpeg_on_progress;
  r.d.progress = &r.ctx.progress;
  if (!read_header(&r.d, &r.ctx, static_cast<const unsigned char*>(data), size)) throw fail();
  check_frame_size(r.d.image_width, r.d.image_height, name);
  J_COLOR_SPACE space = JCS_RGB;
  int channels = 3;
  switch (r.d.jpeg_color_space) {
    case JCS_GRAYSCALE: space = JCS_GRAYSCALE; channels = 1; break;
    case JCS_YCbCr:
    case JCS_RGB: break;
    default:
      throw Error(ErrorCode::InvalidData, name + ": a colour image must be gray or RGB, this JPEG is CMYK/YCCK");
  }
  ColorImage img;
  img.width = r.d.image_width;
  img.height = r.d.image_height;
  img.channels = channels;
  const std::size_t row = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(channels);
  img.bytes.resize(row * img.height);
  if (!read_pixels(&r.d, &r.ctx, space, img.bytes.data(), row)) throw fail();
  return img;
}

bool is_jpeg(const void* data, std::size_t size) {
  const auto* b = static_cast<const unsigned char*>(data);
  return size >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF;
}

}  // namespace sogmm::format::detail
