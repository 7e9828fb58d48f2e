// zstd contexts whose memory comes from the C++ allocator (private).
//
// Why: zstd's own malloc bypasses operator new, so an allocation failure
// inside zstd surfaced as a zstd error ("Allocation error"), which the reader
// reported as a corrupt file (SOGMM_E_FORMAT) instead of out of memory, and
// the out-of-memory sweeps of tests/hardening never reached those
// allocations. Routed through operator new (nothrow), every allocation of a
// save or load is the library's, and a failed one is std::bad_alloc
// (SOGMM_E_NOMEM) wherever it happens.
#pragma once

#define ZSTD_STATIC_LINKING_ONLY  // ZSTD_customMem, ZSTD_create*Ctx_advanced (exported by Debian's libzstd 1.5)
#include <zstd.h>
#include <zstd_errors.h>

#include <cstddef>
#include <memory>
#include <new>

namespace sogmm::format::detail {

inline void* zstd_allocate(void*, std::size_t size) { return ::operator new(size, std::nothrow); }
inline void zstd_release(void*, void* p) { ::operator delete(p); }
inline constexpr ZSTD_customMem kZstdMemory{zstd_allocate, zstd_release, nullptr};

struct DCtxDeleter {
  void operator()(ZSTD_DCtx* d) const { ZSTD_freeDCtx(d); }
};
struct CCtxDeleter {
  void operator()(ZSTD_CCtx* c) const { ZSTD_freeCCtx(c); }
};
using DCtx = std::unique_ptr<ZSTD_DCtx, DCtxDeleter>;
using CCtx = std::unique_ptr<ZSTD_CCtx, CCtxDeleter>;

/// A new decompression context; std::bad_alloc when there is no memory.
inline DCtx new_dctx() {
  DCtx d(ZSTD_createDCtx_advanced(kZstdMemory));
  if (!d) throw std::bad_alloc();
  return d;
}

/// A new compression context; std::bad_alloc when there is no memory.
inline CCtx new_cctx() {
  CCtx c(ZSTD_createCCtx_advanced(kZstdMemory));
  if (!c) throw std::bad_alloc();
  return c;
}

/// Throws std::bad_alloc when a zstd result is an allocation failure (before
/// the caller reports any other zstd error as its own kind).
inline void throw_if_out_of_memory(std::size_t result) {
  if (ZSTD_isError(result) && ZSTD_getErrorCode(result) == ZSTD_error_memory_allocation) throw std::bad_alloc();
}

}  // namespace sogmm::format::detail
