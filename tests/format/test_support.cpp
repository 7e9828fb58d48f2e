#include "test_support.hpp"

#include <cstring>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <cmath>
#include <random>

namespace sogmm::test {

Model synthetic_model(std::size_t m, std::uint32_t seed, bool full_metadata) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  Model model;
  Gmm& g = model.gmm;
  g.resize(m);
  double sum = 0.0;
  std::vector<double> w(m);
  for (auto& x : w) sum += (x = 0.05 + u(rng));
  for (std::size_t k = 0; k < m; ++k) g.weights[k] = static_cast<float>(w[k] / sum);
  for (std::size_t k = 0; k < m; ++k) {
    g.means[4 * k + 0] = static_cast<float>(3.0 * u(rng) - 1.5);
    g.means[4 * k + 1] = static_cast<float>(2.0 * u(rng) - 1.0);
    g.means[4 * k + 2] = static_cast<float>(0.5 + 2.5 * u(rng));
    g.means[4 * k + 3] = static_cast<float>(u(rng));
    double a[4][4], c[4][4];
    for (auto& row : a)
      for (double& x : row) x = 0.02 * n(rng);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        c[i][j] = (i == j ? 1e-6 : 0.0);
        for (int t = 0; t < 4; ++t) c[i][j] += a[i][t] * a[j][t];
      }
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) g.covariances[16 * k + 4 * i + j] = static_cast<float>(i <= j ? c[i][j] : c[j][i]);
  }
  g.support_size = 1000 * m + 7;
  if (full_metadata) {
    model.fit = FitInfo{true, 0.02, 0, 1e-3, 1e-6, 100, 17, true, 1.2345, 42};
    model.camera.known = true;
    model.camera.camera = Camera{640, 480, 525.0, 525.0, 319.5, 239.5};
    model.camera.decimation = 5;
    model.camera.depth_scale = 5000.0;
    model.camera.depth_min = 0.25;
    model.camera.depth_max = 4.0;
    const double c = std::cos(0.3), s = std::sin(0.3);
    model.pose = std::array<double, 16>{c, -s, 0, 1.5, s, c, 0, -0.25, 0, 0, 1, 2.0, 0, 0, 0, 1};
    model.producer_name = "sogmm-tests";
    model.producer_version = "9.8.7";
    model.created_unix_ms = 1700000000123;
    model.key_values = {{"sequence", "livingroom"}, {"frame", "0"}, {"frame", "duplicate keys are kept"}, {"", "\xce\xbb"}};
  }
  return model;
}

std::uint32_t crc32c_bitwise(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0x82F63B78u & (0u - (c & 1u)));
  }
  return c ^ 0xFFFFFFFFu;
}

namespace {
bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}
}  // namespace

float symmetric_tie(float a, float b) {
  std::uint32_t bits;
  std::memcpy(&bits, &a, 4);
  return bits % 2 == 0 ? a : b;
}

bool bit_equal(const Model& a, const Model& b) {
  const FitInfo &fa = a.fit, &fb = b.fit;
  const CameraInfo &ca = a.camera, &cb = b.camera;
  return same_bits(a.gmm.weights, b.gmm.weights) && same_bits(a.gmm.means, b.gmm.means) &&
         same_bits(a.gmm.covariances, b.gmm.covariances) && a.gmm.support_size == b.gmm.support_size &&
         fa.known == fb.known && fa.bandwidth == fb.bandwidth && fa.n_components_requested == fb.n_components_requested &&
         fa.tol == fb.tol && fa.reg_covar == fb.reg_covar && fa.max_iter == fb.max_iter && fa.n_iter == fb.n_iter &&
         fa.converged == fb.converged && fa.log_likelihood == fb.log_likelihood && fa.seed == fb.seed &&
         ca.known == cb.known && ca.camera.width == cb.camera.width && ca.camera.height == cb.camera.height &&
         ca.camera.fx == cb.camera.fx && ca.camera.fy == cb.camera.fy && ca.camera.cx == cb.camera.cx &&
         ca.camera.cy == cb.camera.cy && ca.decimation == cb.decimation && ca.depth_scale == cb.depth_scale &&
         ca.depth_min == cb.depth_min && ca.depth_max == cb.depth_max && a.pose == b.pose &&
         a.producer_name == b.producer_name && a.producer_version == b.producer_version &&
         a.created_unix_ms == b.created_unix_ms && a.key_values == b.key_values;
}

std::string make_scratch_dir(const std::string& prefix) {
  std::string templ = "/tmp/" + prefix + "-XXXXXX";
  if (::mkdtemp(templ.data()) == nullptr) throw std::runtime_error("cannot create a scratch directory " + templ);
  return templ;
}

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    ::closedir(d);
  }
  return out;
}

void remove_scratch_dir(const std::string& dir) {
  ::chmod(dir.c_str(), 0700);
  for (const std::string& f : list_dir(dir)) std::remove((dir + "/" + f).c_str());
  ::rmdir(dir.c_str());
}

std::vector<std::uint8_t> read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace sogmm::test
