// sogmm_trajectory_*: the library's Redwood .log reader and writer
// (sogmm/trajectory_log.hpp) behind the C API.
#include <memory>
#include <string>
#include <vector>

#include "internal.hpp"
#include "sogmm/trajectory_log.hpp"

struct sogmm_trajectory {
  std::vector<double> poses;  ///< 16 per block
  std::vector<int64_t> ids;
};

extern "C" {

SOGMM_API sogmm_status sogmm_trajectory_read(sogmm_trajectory** out, const char* path) {
  SOGMM_TRY {
    sogmm_capi::require_out(out);
    sogmm_capi::require_nonnull(path, "path");
    const sogmm::format::Trajectory t = sogmm::format::read_trajectory_log(path);
    auto h = std::make_unique<sogmm_trajectory>();
    for (const auto& p : t.poses) h->poses.insert(h->poses.end(), p.begin(), p.end());
    h->ids.assign(t.ids.begin(), t.ids.end());
    *out = h.release();
  }
  SOGMM_CATCH
}

SOGMM_API void sogmm_trajectory_free(sogmm_trajectory* trajectory) { delete trajectory; }

SOGMM_API size_t sogmm_trajectory_size(const sogmm_trajectory* trajectory) {
  return trajectory ? trajectory->ids.size() : 0;
}
SOGMM_API const double* sogmm_trajectory_poses(const sogmm_trajectory* trajectory) {
  return trajectory ? trajectory->poses.data() : nullptr;
}
SOGMM_API const int64_t* sogmm_trajectory_ids(const sogmm_trajectory* trajectory) {
  return trajectory ? trajectory->ids.data() : nullptr;
}

SOGMM_API sogmm_status sogmm_trajectory_write(const char* path, const double* poses, size_t n) {
  SOGMM_TRY {
    sogmm_capi::require_nonnull(path, "path");
    if (n == 0) sogmm_capi::fail(SOGMM_E_INVALID_ARG, "n is 0: a trajectory holds at least one pose");
    sogmm_capi::require_nonnull(poses, "poses");
    std::vector<std::array<double, 16>> list(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::string what = "pose " + std::to_string(k);
      list[k] = sogmm_capi::require_rigid(poses + 16 * k, what.c_str());
    }
    sogmm::format::write_trajectory_log(path, list);
  }
  SOGMM_CATCH
}

}  // extern "C"
