// Metadata strings of a model: valid UTF-8, no NUL.
#include "strings.hpp"

#include "container.hpp"
#include "sogmm/metadata_string.hpp"

namespace sogmm::format::detail {

void check_strings(const Model& model, ErrorCode code) {
  auto check = [&](const std::string& s, const std::string& what) {
    const std::string problem = metadata_string_problem(s);
    if (!problem.empty()) fail(code, "bad_metadata", what + ": " + problem);
  };
  check(model.producer_name, "producer name");
  check(model.producer_version, "producer version");
  for (std::size_t i = 0; i < model.key_values.size(); ++i) {
    check(model.key_values[i].first, "key of key/value pair " + std::to_string(i));
    check(model.key_values[i].second, "value of key/value pair " + std::to_string(i));
  }
}

}  // namespace sogmm::format::detail
