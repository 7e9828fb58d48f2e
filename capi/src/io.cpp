// .sogmm save/load by path and to/from memory, through the format library
// (which writes atomically and verifies what it reads).
#include <filesystem>
#include <string>
#include <system_error>

#include "internal.hpp"
#include "sogmm/format.hpp"
#include "sogmm/gmm.hpp"

namespace {

using sogmm_capi::fail;
using sogmm_capi::require_nonnull;

const sogmm::format::WriteOptions& write_options(const sogmm_options& o) { return o.settings.write; }
const sogmm::format::ReadOptions& read_options(const sogmm_options& o) { return o.settings.read; }

void require_path(const char* path) {
  require_nonnull(path, "path");
  if (*path == '\0') fail(SOGMM_E_IO, "path is empty");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    fail(SOGMM_E_IO, std::string("\"") + path + "\" is a directory, not a .sogmm file");
}

/// Wraps a model read by the format library, re-checking the invariants
/// every handle keeps (M >= 1, consistent sizes, finite, SPD) so that no
/// later call can trip over a malformed model.
sogmm_model* wrap(sogmm::Model&& m) {
  sogmm::validate(m.gmm);
  auto handle = std::make_unique<sogmm_model>();
  handle->model = std::move(m);
  return handle.release();
}

}  // namespace

extern "C" {

SOGMM_API sogmm_status sogmm_model_save(const sogmm_model* model, const char* path,
                                        const sogmm_options* options) {
  SOGMM_TRY {
    require_nonnull(model, "model");
    require_path(path);
    sogmm::format::save(path, model->model, write_options(sogmm_capi::opts_or_default(options)));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_load(sogmm_model** out, const char* path, const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    require_path(path);
    *out = wrap(sogmm::format::load(path, read_options(sogmm_capi::opts_or_default(options))));
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_save_to_memory(sogmm_buffer** out, const sogmm_model* model,
                                                  const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    require_nonnull(model, "model");
    auto buffer = std::make_unique<sogmm_buffer>();
    buffer->bytes =
        sogmm::format::to_bytes(model->model, write_options(sogmm_capi::opts_or_default(options)));
    *out = buffer.release();
  }
  SOGMM_CATCH
}

SOGMM_API sogmm_status sogmm_model_load_from_memory(sogmm_model** out, const void* data, size_t size,
                                                    const sogmm_options* options) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    require_nonnull(data, "data");
    if (size == 0) fail(SOGMM_E_FORMAT, "size is 0: an empty buffer is not a .sogmm document");
    *out = wrap(sogmm::format::from_bytes(data, size, read_options(sogmm_capi::opts_or_default(options))));
  }
  SOGMM_CATCH
}

}  // extern "C"
