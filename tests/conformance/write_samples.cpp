// Writes models with today's C++ writer for the Python reader to check
// (tests/conformance/python_reader/test_cpp_writer.py).
// Usage: sogmm_conformance_write_samples OUT_DIR
// Writes OUT_DIR/<name>.sogmm and OUT_DIR/<name>.json (canonical dump).
#include <fstream>
#include <iostream>
#include <random>

#include "sogmm/format.hpp"

namespace {

sogmm::Model model(std::size_t m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sogmm::Model out;
  sogmm::Gmm& g = out.gmm;
  g.resize(m);
  double sum = 0;
  for (auto& w : g.weights) sum += (w = static_cast<float>(0.1 + u(rng)));
  for (auto& w : g.weights) w = static_cast<float>(w / sum);
  for (auto& x : g.means) x = static_cast<float>(u(rng));
  for (std::size_t k = 0; k < m; ++k) {
    double a[4][4];
    for (auto& r : a)
      for (double& x : r) x = 0.1 * (u(rng) - 0.5);
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) {
        double c = i == j ? 1e-4 : 0.0;
        for (int t = 0; t < 4; ++t) c += a[i][t] * a[j][t];
        g.covariances[16 * k + 4 * i + j] = g.covariances[16 * k + 4 * j + i] = static_cast<float>(c);
      }
  }
  g.support_size = 77 * m;
  out.fit = sogmm::FitInfo{true, 0.03, 0, 1e-3, 1e-6, 100, 12, true, 3.5, 99};
  out.key_values = {{"k", "v"}};
  out.created_unix_ms = 1234;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const std::string dir = argv[1];
  struct S {
    const char* name;
    std::size_t m;
    sogmm::format::WriteOptions o;
  } samples[] = {{"c_f32_zstd", 300, {}}, {"c_f64_zstd", 40, {19, true, true}}, {"c_f32_raw", 5, {19, false, false}},
                 {"c_level1", 100, {1, false, true}},
                 // Quantized components (spec/format.md 5.7): the Python reader's decoding formulas must give
                 // the C++ reader's bits on the writer's codes.
                 {"c_quantized", 300, {19, false, true, 0.25}}, {"c_quantized_raw", 30, {19, false, false, 0.5}}};
  for (const S& s : samples) {
    const sogmm::Model m = model(s.m, static_cast<unsigned>(s.m));
    const auto bytes = sogmm::format::to_bytes(m, s.o);
    std::ofstream(dir + "/" + s.name + ".sogmm", std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    const sogmm::format::FileInfo info = sogmm::format::read_info(bytes.data(), bytes.size());
    std::ofstream(dir + "/" + s.name + ".json") << sogmm::format::to_canonical_json(sogmm::format::from_bytes(bytes.data(), bytes.size()), &info);
  }
  return 0;
}
