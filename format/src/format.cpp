// Public entry points of the reader: from_bytes / load / read_info, built from
// the container, schema, codec and checks pieces (the writer is writer.cpp).
#include "sogmm/format.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "checks.hpp"
#include "codec.hpp"
#include "container.hpp"
#include "crc32c.hpp"
#include "internal.hpp"
#include "schema.hpp"

namespace sogmm::format {
namespace detail {
namespace {

std::vector<double> to_doubles(const std::vector<std::uint8_t>& bytes, std::uint8_t dtype) {
  const std::size_t w = dtype == kDTypeF64 ? 8 : 4;
  std::vector<double> out(bytes.size() / w);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (w == 8) {
      const std::uint64_t bits = load_le<std::uint64_t>(&bytes[i * 8]);
      std::memcpy(&out[i], &bits, 8);
    } else {
      const std::uint32_t bits = load_le<std::uint32_t>(&bytes[i * 4]);
      float f;
      std::memcpy(&f, &bits, 4);
      out[i] = f;
    }
  }
  return out;
}

ParsedMetadata read_metadata(const std::uint8_t* p, std::size_t size, const ReadOptions& options) {
  const std::uint8_t* trailer = size >= kTrailerSize ? p + size - kTrailerSize : p;
  const Header h = check_container(p, size, size, trailer, options.verify_checksums);
  return parse_metadata(p + kHeaderSize, h, options);
}

}  // namespace
}  // namespace detail

Model from_bytes(const void* data, std::size_t size, const ReadOptions& options) {
  using namespace detail;
  if (data == nullptr && size != 0) throw Error(ErrorCode::InvalidArgument, "from_bytes: null data");
  const auto* p = static_cast<const std::uint8_t*>(data);
  ParsedMetadata meta = read_metadata(p, size, options);
  const std::uint64_t m = meta.info.n_components;

  // 17-18. decode each array and check its CRC
  std::vector<double> values[3];
  const char* const names[3] = {"weights", "means", "covariances"};
  for (int i = 0; i < 3; ++i) {
    const ArrayRecord& r = meta.arrays[i];
    const Shape shape{m, columns(i, meta.packed), r.dtype == kDTypeF64 ? 8u : 4u};
    const std::vector<std::uint8_t> bytes =
        decode_array(p + r.offset, r.stored_length, shape, Encoding{r.order, r.filter, r.codec});
    if (options.verify_checksums && crc32c(bytes.data(), bytes.size()) != r.crc32c) {
      fail(ErrorCode::Format, "checksum_mismatch", std::string(names[i]) + ": CRC-32C of the decoded bytes does not match");
    }
    values[i] = to_doubles(bytes, r.dtype);
  }

  // 19. value checks
  ArraysView view{m, &values[kWeights], &values[kMeans], &values[kCovariances], meta.packed};
  check_values(view);

  Model model = std::move(meta.info.metadata);
  Gmm& g = model.gmm;
  g.resize(static_cast<std::size_t>(m));
  auto narrow = [&](double v, const char* what, std::uint64_t k) {
    const float f = static_cast<float>(v);
    if (!std::isfinite(f)) {
      fail(ErrorCode::Numeric, "non_finite",
           std::string(what) + " of component " + std::to_string(k) + " overflows float32");
    }
    return f;
  };
  double full[16];
  for (std::uint64_t k = 0; k < m; ++k) {
    g.weights[k] = narrow(values[kWeights][k], "weight", k);
    for (int c = 0; c < 4; ++c) g.means[4 * k + c] = narrow(values[kMeans][4 * k + c], "mean", k);
    if (meta.packed) {
      unpack_upper(&values[kCovariances][10 * k], full);
    } else {
      std::memcpy(full, &values[kCovariances][16 * k], sizeof full);
    }
    for (int c = 0; c < 16; ++c) g.covariances[16 * k + c] = narrow(full[c], "covariance", k);
  }
  return model;
}

FileInfo read_info(const void* data, std::size_t size, const ReadOptions& options) {
  if (data == nullptr && size != 0) throw Error(ErrorCode::InvalidArgument, "read_info: null data");
  return detail::read_metadata(static_cast<const std::uint8_t*>(data), size, options).info;
}

namespace {

std::ifstream open_for_read(const std::string& path, std::uint64_t* size) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw Error(ErrorCode::Io, "cannot open '" + path + "' for reading");
  const std::streamoff end = in.tellg();
  if (end < 0) throw Error(ErrorCode::Io, "cannot determine the size of '" + path + "'");
  *size = static_cast<std::uint64_t>(end);
  in.seekg(0);
  return in;
}

void read_exact(std::ifstream& in, std::uint64_t offset, std::uint8_t* out, std::size_t n, const std::string& path) {
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
  if (!in || static_cast<std::size_t>(in.gcount()) != n) throw Error(ErrorCode::Io, "cannot read '" + path + "'");
}

}  // namespace

Model load(const std::string& path, const ReadOptions& options) {
  std::uint64_t size = 0;
  std::ifstream in = open_for_read(path, &size);
  if (size > std::numeric_limits<std::size_t>::max()) throw Error(ErrorCode::Io, "'" + path + "' is too large");
  // The file's own size bounds this allocation (it is what is on disk).
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  if (size > 0) read_exact(in, 0, bytes.data(), bytes.size(), path);
  return from_bytes(bytes.data(), bytes.size(), options);
}

FileInfo read_info_file(const std::string& path, const ReadOptions& options) {
  using namespace detail;
  std::uint64_t size = 0;
  std::ifstream in = open_for_read(path, &size);
  std::vector<std::uint8_t> prefix(static_cast<std::size_t>(std::min<std::uint64_t>(size, kHeaderSize)));
  if (!prefix.empty()) read_exact(in, 0, prefix.data(), prefix.size(), path);
  std::uint8_t trailer[kTrailerSize] = {};
  if (size >= kTrailerSize) read_exact(in, size - kTrailerSize, trailer, kTrailerSize, path);
  if (prefix.size() == kHeaderSize && std::memcmp(prefix.data(), kMagic.data(), kMagic.size()) == 0) {
    const std::uint64_t want = std::min<std::uint64_t>(size, kHeaderSize + load_le<std::uint32_t>(&prefix[24]));
    prefix.resize(static_cast<std::size_t>(want));
    if (want > kHeaderSize) read_exact(in, kHeaderSize, prefix.data() + kHeaderSize, want - kHeaderSize, path);
  }
  const Header h = check_container(prefix.data(), prefix.size(), size, trailer, options.verify_checksums);
  return parse_metadata(prefix.data() + kHeaderSize, h, options).info;
}

}  // namespace sogmm::format
