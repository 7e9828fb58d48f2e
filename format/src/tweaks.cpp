// Test hook: a float64 value patched into a written file (internal.hpp).
#include <cstring>
#include <stdexcept>

#include "container.hpp"
#include "crc32c.hpp"
#include "internal.hpp"
#include "schema.hpp"

namespace sogmm::format::detail {
namespace {

// Position in `meta` of field `id` of the table at `table` (FlatBuffers
// encoding, spec/format.md section 4.1), or 0 when the field is absent.
std::size_t field(const std::uint8_t* meta, std::size_t table, int id) {
  const std::size_t vtable = table - static_cast<std::size_t>(load_le<std::int32_t>(meta + table));
  const std::uint16_t vtable_size = load_le<std::uint16_t>(meta + vtable);
  const std::size_t slot = 4 + 2 * static_cast<std::size_t>(id);
  const std::uint16_t at = slot < vtable_size ? load_le<std::uint16_t>(meta + vtable + slot) : 0;
  return at == 0 ? 0 : table + at;
}

}  // namespace

void patch_f64_value(std::vector<std::uint8_t>& file, int which, std::uint64_t index, double value) {
  ReadOptions unchecked;
  unchecked.verify_checksums = false;
  const FileInfo info = read_info(file.data(), file.size(), unchecked);
  const ArrayInfo& a = which == kWeights ? info.weights : which == kMeans ? info.means : info.covariances;
  if (a.dtype != "f64" || a.codec != "none" || a.order != "component_major" || index >= a.decoded_length / 8) {
    throw std::logic_error("patch_f64_value: needs an uncompressed float64 file and an element of the array");
  }
  std::uint64_t bits;
  std::memcpy(&bits, &value, 8);
  store_le<std::uint64_t>(&file[a.offset + 8 * index], bits);
  // The Array table's crc32c field (id 7) of root field 4 + which, in place.
  std::uint8_t* meta = &file[kHeaderSize];
  const std::size_t root = load_le<std::uint32_t>(meta);
  const std::size_t ref = field(meta, root, 4 + which);
  const std::size_t crc_at = ref == 0 ? 0 : field(meta, ref + load_le<std::uint32_t>(meta + ref), 7);
  if (crc_at == 0) throw std::logic_error("patch_f64_value: the array's crc32c field is absent");
  store_le<std::uint32_t>(meta + crc_at, crc32c(&file[a.offset], a.decoded_length));
  refresh_metadata_crc(file);
}

}  // namespace sogmm::format::detail
