// Small input files (images, trajectories, intrinsics) read whole, by one
// rule for the library and the tools: a regular file only, opened without
// blocking, of bounded size.
#pragma once

#include <cstdint>
#include <string>

namespace sogmm::format {

/// The content of a small input file of at most `max_bytes` bytes. Opened
/// without blocking and refused with Error(Io) unless it is a regular file
/// (a FIFO fails at once instead of waiting for a writer); a larger file ->
/// Error(Limit). `what` names it in messages ("trajectory").
std::string read_input_file(const std::string& path, const std::string& what, std::uint64_t max_bytes);

/// What a file that is not a regular file is, for messages: "a directory",
/// "a FIFO", "a socket", "a device" or "not a regular file" (`mode`: st_mode).
const char* file_kind(unsigned mode);

}  // namespace sogmm::format
