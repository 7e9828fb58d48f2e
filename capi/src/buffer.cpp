// sogmm_buffer: bytes produced by the library (save_to_memory).
#include "internal.hpp"

extern "C" {

SOGMM_API const uint8_t* sogmm_buffer_data(const sogmm_buffer* buffer) {
  if (!buffer) return nullptr;
  return buffer->bytes.data();
}

SOGMM_API size_t sogmm_buffer_size(const sogmm_buffer* buffer) {
  if (!buffer) return 0;
  return buffer->bytes.size();
}

SOGMM_API void sogmm_buffer_free(sogmm_buffer* buffer) { delete buffer; }

}  // extern "C"
