// Canonical JSON dump of a model (spec/format.md section 10).
#include <nlohmann/json.hpp>

#include "sogmm/format.hpp"
#include "strings.hpp"

namespace sogmm::format {
namespace {

using ojson = nlohmann::ordered_json;

ojson array_json(const ArrayInfo& a) {
  ojson j;
  j["dtype"] = a.dtype;
  j["order"] = a.order;
  j["filter"] = a.filter;
  j["codec"] = a.codec;
  j["offset"] = a.offset;
  j["stored_length"] = a.stored_length;
  j["decoded_length"] = a.decoded_length;
  j["crc32c"] = a.crc32c;
  return j;
}

}  // namespace

std::string to_canonical_json(const Model& model, const FileInfo* info) {
  detail::check_strings(model, ErrorCode::InvalidData);
  ojson j;
  if (info != nullptr) {
    ojson f;
    f["format_version"] = std::to_string(info->format_major) + "." + std::to_string(info->format_minor);
    f["file_length"] = info->file_length;
    f["metadata_length"] = info->metadata_length;
    f["features_required"] = info->features_required;
    f["features_used"] = info->features_used;
    f["covariance_layout"] = info->covariance_layout;
    f["weights"] = array_json(info->weights);
    f["means"] = array_json(info->means);
    f["covariances"] = array_json(info->covariances);
    j["file"] = f;
  }
  const Gmm& g = model.gmm;
  const std::size_t m = g.size();
  j["n_components"] = info != nullptr ? info->n_components : static_cast<std::uint64_t>(m);
  j["support_size"] = g.support_size;
  j["axis_labels"] = {"x", "y", "z", "gray"};
  j["axis_units"] = {"m", "m", "m", "1"};
  if (model.fit.known) {
    const FitInfo& f = model.fit;
    j["fit"] = {{"bandwidth", f.bandwidth},   {"n_components_requested", f.n_components_requested},
                {"tol", f.tol},               {"reg_covar", f.reg_covar},
                {"max_iter", f.max_iter},     {"n_iter", f.n_iter},
                {"converged", f.converged},   {"log_likelihood", f.log_likelihood},
                {"seed", f.seed}};
  } else {
    j["fit"] = nullptr;
  }
  if (model.camera.known) {
    const CameraInfo& c = model.camera;
    j["camera"] = {{"width", c.camera.width}, {"height", c.camera.height}, {"fx", c.camera.fx},
                   {"fy", c.camera.fy},       {"cx", c.camera.cx},         {"cy", c.camera.cy},
                   {"decimation", c.decimation}, {"depth_scale", c.depth_scale},
                   {"depth_min", c.depth_min},   {"depth_max", c.depth_max}};
  } else {
    j["camera"] = nullptr;
  }
  if (model.pose) {
    j["pose"] = ojson::array();
    for (double v : *model.pose) j["pose"].push_back(v);
  } else {
    j["pose"] = nullptr;
  }
  j["producer_name"] = model.producer_name;
  j["producer_version"] = model.producer_version;
  j["created_unix_ms"] = model.created_unix_ms;
  j["key_values"] = ojson::array();
  for (const auto& kv : model.key_values) j["key_values"].push_back({kv.first, kv.second});
  // Arrays only when present (a metadata-only Model has none).
  if (m > 0 && g.means.size() == 4 * m && g.covariances.size() == 16 * m) {
    ojson w = ojson::array(), mu = ojson::array(), cov = ojson::array();
    for (std::size_t k = 0; k < m; ++k) {
      w.push_back(static_cast<double>(g.weights[k]));
      ojson row = ojson::array();
      for (int c = 0; c < 4; ++c) row.push_back(static_cast<double>(g.means[4 * k + c]));
      mu.push_back(row);
      ojson mat = ojson::array();
      for (int r = 0; r < 4; ++r) {
        ojson mrow = ojson::array();
        for (int c = 0; c < 4; ++c) mrow.push_back(static_cast<double>(g.covariances[16 * k + 4 * r + c]));
        mat.push_back(mrow);
      }
      cov.push_back(mat);
    }
    j["weights"] = w;
    j["means"] = mu;
    j["covariances"] = cov;
  }
  return j.dump(2) + "\n";  // strings checked above: valid UTF-8, so dump() cannot throw
}

}  // namespace sogmm::format
