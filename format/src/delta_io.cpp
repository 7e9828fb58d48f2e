// Map delta files (sogmm/map_delta_file.hpp): the model container with the
// map_delta feature bit, the delta keys carried as key_values.
#include "sogmm/map_delta_file.hpp"

#include "internal.hpp"
#include "source.hpp"
#include "sogmm/format.hpp"

namespace sogmm::format {

std::vector<std::uint8_t> delta_to_bytes(const MapDelta& delta, const WriteOptions& options) {
  return detail::encode(delta_to_model(delta), options, detail::map_delta_tweaks());
}

MapDelta delta_from_bytes(const void* data, std::size_t size, const ReadOptions& options) {
  if (data == nullptr && size != 0) throw Error(ErrorCode::InvalidArgument, "delta_from_bytes: null data");
  const detail::MemorySource src(static_cast<const std::uint8_t*>(data), size);
  return delta_from_model(detail::read_model(src, options, nullptr, true));
}

void save_delta(const std::string& path, const MapDelta& delta, const WriteOptions& options) {
  const std::vector<std::uint8_t> bytes = delta_to_bytes(delta, options);
  write_file(path, bytes.data(), bytes.size());
}

MapDelta load_delta(const std::string& path, const ReadOptions& options) {
  const detail::FileSource src(path);
  return delta_from_model(detail::read_model(src, options, nullptr, true));
}

}  // namespace sogmm::format
