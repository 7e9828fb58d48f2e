// Where a reader takes the bytes of a file from: a buffer in memory or an
// open regular file. The reader fetches the header, the metadata block and
// each array's stored bytes separately, so a file is never held whole in
// memory (spec/format.md section 8).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace sogmm::format::detail {

class Source {
 public:
  virtual ~Source() = default;
  /// Size of the file in bytes.
  virtual std::uint64_t size() const = 0;
  /// Copies n bytes at `offset` (offset + n <= size()) into out; throws Error(Io).
  virtual void read(std::uint64_t offset, std::uint8_t* out, std::size_t n) const = 0;
  /// The n bytes at `offset` without copying, or null when the source cannot
  /// hand them out (a file).
  virtual const std::uint8_t* view(std::uint64_t offset, std::size_t n) const = 0;
};

/// Bytes owned by the caller.
class MemorySource final : public Source {
 public:
  MemorySource(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint64_t size() const override { return size_; }
  void read(std::uint64_t offset, std::uint8_t* out, std::size_t n) const override;
  const std::uint8_t* view(std::uint64_t offset, std::size_t n) const override;

 private:
  const std::uint8_t* data_;
  std::size_t size_;
};

/// A regular file, opened without blocking: a FIFO, a device or a directory
/// is refused with Error(Io) instead of waiting for a writer.
class FileSource final : public Source {
 public:
  explicit FileSource(const std::string& path);
  ~FileSource() override;
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;
  std::uint64_t size() const override { return size_; }
  void read(std::uint64_t offset, std::uint8_t* out, std::size_t n) const override;
  const std::uint8_t* view(std::uint64_t, std::size_t) const override { return nullptr; }

 private:
  std::string path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

}  // namespace sogmm::format::detail
