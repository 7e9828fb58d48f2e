// Small file helpers shared by the sogmm tools.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace sogmm::tools {

/// Writes `size` bytes to `path` atomically: a temporary file next to it
/// (path + ".tmp-<pid>") is written, flushed to disk and renamed over `path`.
/// On failure nothing is left behind and Error(Io) names the file and the
/// problem (missing folder, permission, disk full).
void write_file_atomic(const std::string& path, const void* data, std::size_t size);

/// Checks up front that `path` can be written (its folder exists, it is not
/// a folder), so a long computation does not end in an I/O error.
void check_output_path(const std::string& path);

/// Size of a file in bytes (0 when it cannot be read).
std::uint64_t file_size_or_zero(const std::string& path);

}  // namespace sogmm::tools
