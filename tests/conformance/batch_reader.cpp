// Reads many .sogmm files with the C++ reader, one verdict per line, for the
// mutation test (tests/conformance/mutation_test.py): one process for
// thousands of files keeps the test fast.
// Usage: sogmm_conformance_batch LIST   (LIST: one path per line)
// Output, one line per path: "accept <canonical JSON dump, compact>" or
// "reject <category> <reason>".
#include <fstream>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "common.hpp"
#include "sogmm/format.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " LIST\n";
    return 2;
  }
  std::ifstream list(argv[1]);
  if (!list) {
    std::cerr << "cannot open " << argv[1] << "\n";
    return 2;
  }
  std::string path;
  while (std::getline(list, path)) {
    const std::vector<std::uint8_t> bytes = sogmm_conformance::slurp(path);
    try {
      const sogmm::Model model = sogmm::format::from_bytes(bytes.data(), bytes.size());
      const sogmm::format::FileInfo info = sogmm::format::read_info(bytes.data(), bytes.size());
      std::cout << "accept " << nlohmann::ordered_json::parse(sogmm::format::to_canonical_json(model, &info)).dump() << "\n";
    } catch (const sogmm::format::FormatError& e) {
      std::cout << "reject " << sogmm_conformance::category_of(e.code()) << " " << e.reason() << "\n";
    } catch (const std::exception& e) {
      std::cout << "error " << e.what() << "\n";  // never expected: counts as a disagreement
    }
  }
  return 0;
}
