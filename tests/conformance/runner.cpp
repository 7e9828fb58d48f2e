// Runs our C++ reader over spec/conformance/manifest.json: every valid vector
// must load and dump to exactly its expected canonical JSON, every invalid
// one must be rejected with the expected category and reason.
// Usage: sogmm_conformance_runner CONFORMANCE_DIR   (exit 0 when all pass)
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common.hpp"
#include "sogmm/format.hpp"

namespace {

using sogmm_conformance::category_of;
using sogmm_conformance::slurp;

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " CONFORMANCE_DIR\n";
    return 2;
  }
  const std::string dir = argv[1];
  std::ifstream mf(dir + "/manifest.json");
  if (!mf) {
    std::cerr << "cannot open " << dir << "/manifest.json\n";
    return 2;
  }
  const nlohmann::json manifest = nlohmann::json::parse(mf);
  int failures = 0, count = 0, valid = 0;
  for (const auto& v : manifest.at("vectors")) {
    ++count;
    const std::string file = v.at("file");
    const std::vector<std::uint8_t> bytes = slurp(dir + "/" + file);
    std::string outcome;
    try {
      const sogmm::Model model = sogmm::format::from_bytes(bytes.data(), bytes.size());
      const sogmm::format::FileInfo info = sogmm::format::read_info(bytes.data(), bytes.size());
      if (v.at("expect") == "valid") {
        const auto expected = nlohmann::json::parse(slurp(dir + "/" + v.at("json").get<std::string>()));
        const auto got = nlohmann::json::parse(sogmm::format::to_canonical_json(model, &info));
        outcome = got == expected ? "" : "decoded model differs from " + v.at("json").get<std::string>();
        if (outcome.empty()) ++valid;
      } else {
        outcome = "accepted, expected " + v.at("reason").get<std::string>();
      }
    } catch (const sogmm::format::FormatError& e) {
      if (v.at("expect") == "valid") {
        outcome = std::string("rejected: ") + e.what();
      } else if (e.reason() != v.at("reason") || category_of(e.code()) != v.at("category")) {
        outcome = std::string("rejected as ") + category_of(e.code()) + "/" + e.reason() + ", expected " +
                  v.at("category").get<std::string>() + "/" + v.at("reason").get<std::string>() + " (" + e.what() + ")";
      }
    } catch (const std::exception& e) {
      outcome = std::string("unexpected exception: ") + e.what();
    }
    if (!outcome.empty()) {
      ++failures;
      std::cout << "FAIL " << file << ": " << outcome << "\n";
    }
  }
  std::cout << count - failures << "/" << count << " vectors pass (" << valid << " valid decoded exactly)\n";
  return failures == 0 && count > 0 ? 0 : 1;
}
