// Map delta files of a folder (map_deltas.hpp).
#include "map_deltas.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "sogmm/error.hpp"
#include "sogmm/format.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/map_delta_file.hpp"

namespace sogmm::tools {

std::string delta_file_name(std::uint64_t revision) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "delta-%012llu.sogmm", static_cast<unsigned long long>(revision));
  return buf;
}

DeltaWriter::DeltaWriter(std::string dir) : dir_(std::move(dir)) {
  if (dir_.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  require(!ec && std::filesystem::is_directory(dir_), ErrorCode::Io,
          "--deltas " + dir_ + ": cannot create the folder" + (ec ? ": " + ec.message() : std::string()));
}

void DeltaWriter::write(const Map& map) {
  if (dir_.empty() || map.revision() == since_) return;
  const std::vector<std::uint8_t> bytes = format::delta_to_bytes(map.delta_since(since_));
  format::write_file((std::filesystem::path(dir_) / delta_file_name(map.revision())).string(), bytes.data(),
                     bytes.size());
  since_ = map.revision();
  ++count_;
  bytes_ += bytes.size();
}

std::vector<std::string> delta_files(const std::string& dir) {
  std::error_code ec;
  std::vector<std::string> out;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("delta-", 0) == 0 && it->path().extension() == ".sogmm") out.push_back(it->path().string());
  }
  require(!ec, ErrorCode::Io, dir + ": cannot list the folder: " + ec.message());
  require(!out.empty(), ErrorCode::InvalidArgument, dir + ": no delta-*.sogmm file");
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace sogmm::tools
