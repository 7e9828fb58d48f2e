// Model::key_values by key (see sogmm/model.hpp).
#include <algorithm>

#include "sogmm/model.hpp"

namespace sogmm {

const std::string* find_value(const Model& model, const std::string& key) {
  for (const auto& kv : model.key_values)
    if (kv.first == key) return &kv.second;
  return nullptr;
}

void set_value(Model& model, const std::string& key, std::string value) {
  for (auto& kv : model.key_values)
    if (kv.first == key) {
      kv.second = std::move(value);
      return;
    }
  model.key_values.emplace_back(key, std::move(value));
}

void erase_value(Model& model, const std::string& key) {
  auto& kvs = model.key_values;
  kvs.erase(std::remove_if(kvs.begin(), kvs.end(), [&](const auto& kv) { return kv.first == key; }), kvs.end());
}

}  // namespace sogmm
