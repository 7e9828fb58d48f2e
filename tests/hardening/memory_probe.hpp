// Resident memory of this process, from /proc/self/status (Linux), for tests
// that check that a call refuses or streams before allocating much.
#pragma once

#include <fstream>
#include <string>

namespace sogmm::test {

/// A "Name:  123 kB" field of /proc/self/status in bytes, or -1.
inline long long status_bytes(const char* field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field, 0) == 0) return 1024 * std::stoll(line.substr(std::string(field).size()));
  }
  return -1;
}

/// Resets the peak (VmHWM) to the current resident size; false when the
/// kernel does not support it (then peak_bytes() cannot be trusted).
inline bool reset_peak() {
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.flush();
  return static_cast<bool>(clear) && status_bytes("VmHWM:") > 0;
}

inline long long peak_bytes() { return status_bytes("VmHWM:"); }
inline long long resident_bytes() { return status_bytes("VmRSS:"); }

}  // namespace sogmm::test
