#include "ply.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <vector>

#include "file_util.hpp"
#include "sogmm/error.hpp"

namespace sogmm::tools {

namespace {
static_assert(sizeof(float) == 4, "float must be 32-bit");

bool little_endian() {
  const std::uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

void put(std::vector<unsigned char>& out, const void* p, std::size_t n) {
  const auto* c = static_cast<const unsigned char*>(p);
  if (little_endian()) {
    out.insert(out.end(), c, c + n);
  } else {
    for (std::size_t i = 0; i < n; ++i) out.push_back(c[n - 1 - i]);
  }
}
void put_f(std::vector<unsigned char>& out, float v) { put(out, &v, 4); }
void put_i(std::vector<unsigned char>& out, std::int32_t v) { put(out, &v, 4); }

std::uint8_t to_u8(float g) {
  if (!(g > 0.f)) return 0;
  if (g >= 1.f) return 255;
  return static_cast<std::uint8_t>(std::lround(g * 255.f));
}

std::string clean_comment(std::string c) {
  std::replace(c.begin(), c.end(), '\n', ' ');
  std::replace(c.begin(), c.end(), '\r', ' ');
  return c;
}

// Unit icosphere: 12 vertices subdivided `levels` times.
void icosphere(int levels, std::vector<std::array<double, 3>>& v, std::vector<std::array<int, 3>>& f) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
       {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
       {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
       {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  auto normalize = [](std::array<double, 3>& a) {
    const double n = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (double& x : a) x /= n;
  };
  for (auto& a : v) normalize(a);
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      std::array<double, 3> m{(v[a][0] + v[b][0]) / 2, (v[a][1] + v[b][1]) / 2, (v[a][2] + v[b][2]) / 2};
      normalize(m);
      v.push_back(m);
      const int id = static_cast<int>(v.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> next;
    next.reserve(f.size() * 4);
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    f.swap(next);
  }
}
}  // namespace

void write_ply_points(const std::string& path, const float* xyzg, std::size_t n, const std::string& comment) {
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  if (!comment.empty()) header += "comment " + clean_comment(comment) + "\n";
  header += "element vertex " + std::to_string(n) +
            "\nproperty float x\nproperty float y\nproperty float z\nproperty float intensity\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  std::vector<unsigned char> out(header.begin(), header.end());
  out.reserve(out.size() + n * 19);
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = xyzg + 4 * i;
    put_f(out, p[0]);
    put_f(out, p[1]);
    put_f(out, p[2]);
    put_f(out, p[3]);
    const std::uint8_t g = to_u8(p[3]);
    out.push_back(g);
    out.push_back(g);
    out.push_back(g);
  }
  write_file_atomic(path, out.data(), out.size());
}

std::size_t write_ply_ellipsoids(const std::string& path, const Gmm& gmm, double sigmas, int subdivisions,
                                 const std::string& comment) {
  std::vector<std::array<double, 3>> sv;
  std::vector<std::array<int, 3>> sf;
  icosphere(subdivisions, sv, sf);
  const std::size_t m = gmm.size(), nv = sv.size() * m, nf = sf.size() * m;
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  if (!comment.empty()) header += "comment " + clean_comment(comment) + "\n";
  header += "element vertex " + std::to_string(nv) +
            "\nproperty float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\n"
            "element face " + std::to_string(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<unsigned char> out(header.begin(), header.end());
  out.reserve(out.size() + nv * 15 + nf * 13);
  for (std::size_t c = 0; c < m; ++c) {
    const float* mu = gmm.mean(c);
    const float* s = gmm.covariance(c);
    // Cholesky of the spatial block (row-major 4x4, top-left 3x3), in double.
    double a[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a[i][j] = 0.5 * (static_cast<double>(s[4 * i + j]) + s[4 * j + i]);
    double l[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    for (int j = 0; j < 3; ++j) {
      double d = a[j][j];
      for (int k = 0; k < j; ++k) d -= l[j][k] * l[j][k];
      require(d > 0 && std::isfinite(d), ErrorCode::Numeric,
              "component " + std::to_string(c) + ": spatial covariance is not positive definite");
      l[j][j] = std::sqrt(d);
      for (int i = j + 1; i < 3; ++i) {
        double x = a[i][j];
        for (int k = 0; k < j; ++k) x -= l[i][k] * l[j][k];
        l[i][j] = x / l[j][j];
      }
    }
    const std::uint8_t g = to_u8(mu[3]);
    for (const auto& u : sv) {
      for (int i = 0; i < 3; ++i) {
        double x = 0;
        for (int k = 0; k <= i; ++k) x += l[i][k] * u[k];
        put_f(out, static_cast<float>(mu[i] + sigmas * x));
      }
      out.push_back(g);
      out.push_back(g);
      out.push_back(g);
    }
  }
  for (std::size_t c = 0; c < m; ++c) {
    const std::int32_t base = static_cast<std::int32_t>(c * sv.size());
    for (const auto& t : sf) {
      out.push_back(3);
      for (int k = 0; k < 3; ++k) put_i(out, base + t[k]);
    }
  }
  write_file_atomic(path, out.data(), out.size());
  return nv;
}

}  // namespace sogmm::tools
