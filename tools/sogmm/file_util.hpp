// The tools' files: every file a tool writes and every small input it reads
// goes through here, so one set of rules holds for all of them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sogmm::tools {

/// Writes `size` bytes to `path` atomically by the mechanism model saves use
/// (sogmm::format::write_file): written through a symbolic link, a target
/// that exists and is not a regular file (a device, a FIFO) refused and left
/// alone, the previous file untouched on failure. Throws Error(Io) naming it.
void write_file_atomic(const std::string& path, const void* data, std::size_t size);

/// Checks up front that `path` can be written, so that a long run does not
/// end in an I/O error: its folder exists and is writable, and the file it
/// names (through symbolic links) is absent or a regular file.
/// Throws Error(Io) naming the path and the problem.
void check_output_path(const std::string& path);

/// One file a command reads or writes, with the flag that named it.
struct NamedFile {
  std::string flag;  ///< e.g. "--csv"
  std::string path;  ///< "" = not used
};

/// Checks every output with check_output_path and refuses (Error(InvalidArgument))
/// an output that is also one of the inputs or another output: the same file
/// by name, through symbolic links or as a hard link. Called before any work.
void check_outputs(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs);

/// Largest small input file read whole (1 GiB).
constexpr std::uint64_t kMaxInputFileBytes = std::uint64_t{1} << 30;

/// The content of a small input file (intrinsics), by the library's rule
/// (format::read_input_file): opened without blocking and refused with
/// Error(Io) unless it is a regular file, so a FIFO or a device fails at
/// once instead of waiting for a writer; above kMaxInputFileBytes Error(Limit).
std::string read_input_file(const std::string& path, const std::string& what);

/// Size of a file in bytes (0 when it cannot be read).
std::uint64_t file_size_or_zero(const std::string& path);

}  // namespace sogmm::tools
