#include "render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm::tools {

namespace {

const cv::Vec3b kEmpty(70, 100, 70);  // BGR dull green: "no data" in every panel

// Regress gray and stddev at rows of 4 floats (xyz used).
void regress(const Gmm& gmm, const std::vector<float>& xyzg, std::vector<float>& gray, std::vector<float>& sd) {
  const std::size_t n = xyzg.size() / 4;
  std::vector<float> xyz(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) xyz[3 * i + k] = xyzg[4 * i + k];
  gray.assign(n, 0.f);
  std::vector<float> var(n, 0.f);
  if (n > 0) regress_gray(gmm, xyz.data(), n, gray.data(), var.data());
  sd.resize(n);
  for (std::size_t i = 0; i < n; ++i) sd[i] = std::sqrt(std::max(var[i], 0.f));
}

struct RayComponent {
  double p[6];   // precision, upper triangle: xx xy xz yy yz zz
  double pm[3];  // P mu
  double mpm;    // mu^T P mu
  double log_amp;  // log w - 1.5 log 2 pi - 0.5 log det Sigma
};

std::vector<RayComponent> ray_components(const Gmm& gmm) {
  std::vector<RayComponent> out(gmm.size());
  for (std::size_t m = 0; m < gmm.size(); ++m) {
    const float* s = gmm.covariance(m);
    const float* mu = gmm.mean(m);
    const double a = s[0], b = s[1], c = s[2], d = s[5], e = s[6], f = s[10];
    // Inverse of the symmetric 3x3 [[a b c][b d e][c e f]] by cofactors.
    const double A = d * f - e * e, B = c * e - b * f, C = b * e - c * d;
    const double det = a * A + b * B + c * C;
    require(det > 0 && std::isfinite(det), ErrorCode::Numeric,
            "component " + std::to_string(m) + ": spatial covariance is not positive definite");
    const double D = a * f - c * c, E = b * c - a * e, F = a * d - b * b;
    RayComponent& r = out[m];
    r.p[0] = A / det; r.p[1] = B / det; r.p[2] = C / det;
    r.p[3] = D / det; r.p[4] = E / det; r.p[5] = F / det;
    const double x = mu[0], y = mu[1], z = mu[2];
    r.pm[0] = r.p[0] * x + r.p[1] * y + r.p[2] * z;
    r.pm[1] = r.p[1] * x + r.p[3] * y + r.p[4] * z;
    r.pm[2] = r.p[2] * x + r.p[4] * y + r.p[5] * z;
    r.mpm = x * r.pm[0] + y * r.pm[1] + z * r.pm[2];
    const double w = gmm.weights[m];
    r.log_amp = (w > 0 ? std::log(w) : -std::numeric_limits<double>::infinity()) -
                1.5 * std::log(2 * M_PI) - 0.5 * std::log(det);
  }
  return out;
}

}  // namespace

RenderedView render_at_points(const Gmm& gmm, const std::vector<float>& xyzg, const Camera& camera) {
  std::vector<float> gray, sd;
  regress(gmm, xyzg, gray, sd);
  const std::size_t n = xyzg.size() / 4;
  std::vector<float> depth(n);
  for (std::size_t i = 0; i < n; ++i) depth[i] = xyzg[4 * i + 2];
  const PointsView view{xyzg.data(), n};
  RenderedView r;
  r.width = camera.width;
  r.height = camera.height;
  r.gray = project_to_image(view, gray.data(), camera, -1.f);
  r.stddev = project_to_image(view, sd.data(), camera, -1.f);
  r.depth = project_to_image(view, depth.data(), camera, -1.f);
  return r;
}

RenderedView render_expected_surface(const Gmm& gmm, const Camera& camera, double depth_min, double depth_max,
                                     double max_mahalanobis) {
  validate(camera);
  const std::vector<RayComponent> comps = ray_components(gmm);
  const std::size_t pixels = static_cast<std::size_t>(camera.width) * camera.height;
  std::vector<float> depth(pixels, -1.f);
  const double r_show = max_mahalanobis * max_mahalanobis;
  const double r_use = std::max(r_show, 64.0);  // components within 8 sigma shape the 1-D mixture
#pragma omp parallel for schedule(dynamic, 4)
  for (int v = 0; v < camera.height; ++v) {
    struct Term { double t, a, log_c; };
    std::vector<Term> terms;
    std::vector<double> starts;
    for (int u = 0; u < camera.width; ++u) {
      const double d[3] = {(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0};
      terms.clear();
      starts.clear();
      for (const RayComponent& c : comps) {
        const double a = c.p[0] * d[0] * d[0] + c.p[3] * d[1] * d[1] + c.p[5] * d[2] * d[2] +
                         2 * (c.p[1] * d[0] * d[1] + c.p[2] * d[0] * d[2] + c.p[4] * d[1] * d[2]);
        const double b = c.pm[0] * d[0] + c.pm[1] * d[1] + c.pm[2] * d[2];
        const double t = b / a;
        const double r = c.mpm - b * b / a;  // squared Mahalanobis distance of the ray to the mean
        if (r > r_use || t <= 0) continue;
        terms.push_back({t, a, c.log_amp - 0.5 * r});
        if (r <= r_show && t > depth_min && t <= depth_max) starts.push_back(t);
      }
      if (starts.empty()) continue;
      // The first surface a camera would see: the nearest mode of the ray's
      // 1-D mixture that a component peak on the ray climbs to (a denser
      // surface behind it is occluded, however dense).
      double best_t = -1;
      double max_log_c = -std::numeric_limits<double>::infinity();
      for (const Term& q : terms) max_log_c = std::max(max_log_c, q.log_c);
      for (double t : starts) {
        bool supported = true;
        for (int it = 0; it < 50; ++it) {  // 1-D mean shift towards a mode of the ray mixture
          double num = 0, den = 0;
          for (const Term& q : terms) {
            const double w = std::exp(q.log_c - max_log_c - 0.5 * q.a * (t - q.t) * (t - q.t)) * q.a;
            num += w * q.t;
            den += w;
          }
          // No density here relative to the ray's strongest term (e.g. the peak
          // of a weight-0 component): not a surface.
          supported = den > 0;
          if (!supported) break;
          const double next = num / den;
          const bool done = std::abs(next - t) < 1e-6;
          t = next;
          if (done) break;
        }
        if (!supported || !(t > depth_min && t <= depth_max)) continue;
        if (best_t < 0 || t < best_t) best_t = t;
      }
      if (best_t > 0) depth[static_cast<std::size_t>(v) * camera.width + u] = static_cast<float>(best_t);
    }
  }
  // Regress at the chosen depths.
  std::vector<float> pts;
  std::vector<std::size_t> where;
  for (std::size_t i = 0; i < pixels; ++i) {
    if (depth[i] < 0) continue;
    const int u = static_cast<int>(i % camera.width), v = static_cast<int>(i / camera.width);
    const double z = depth[i];
    pts.push_back(static_cast<float>((u - camera.cx) / camera.fx * z));
    pts.push_back(static_cast<float>((v - camera.cy) / camera.fy * z));
    pts.push_back(static_cast<float>(z));
    pts.push_back(0.f);
    where.push_back(i);
  }
  std::vector<float> gray, sd;
  regress(gmm, pts, gray, sd);
  RenderedView r;
  r.width = camera.width;
  r.height = camera.height;
  r.depth = depth;
  r.gray.assign(pixels, -1.f);
  r.stddev.assign(pixels, -1.f);
  for (std::size_t k = 0; k < where.size(); ++k) {
    r.gray[where[k]] = gray[k];
    r.stddev[where[k]] = sd[k];
  }
  return r;
}

std::vector<std::uint8_t> gray_to_u8(const std::vector<float>& values) {
  std::vector<std::uint8_t> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const float g = values[i];
    out[i] = g <= 0.f ? 0 : g >= 1.f ? 255 : static_cast<std::uint8_t>(std::lround(g * 255.f));
  }
  return out;
}

namespace {

cv::Mat upscale(const cv::Mat& img, int scale) {
  if (scale == 1) return img.clone();
  cv::Mat out;
  cv::resize(img, out, cv::Size(img.cols * scale, img.rows * scale), 0, 0, cv::INTER_NEAREST);
  return out;
}

cv::Mat gray_panel(const std::vector<float>& values, int w, int h, int scale) {
  cv::Mat img(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const float g = values[static_cast<std::size_t>(v) * w + u];
      if (g < 0) {
        img.at<cv::Vec3b>(v, u) = kEmpty;
      } else {
        const auto b = static_cast<std::uint8_t>(std::lround(std::clamp(g, 0.f, 1.f) * 255.f));
        img.at<cv::Vec3b>(v, u) = cv::Vec3b(b, b, b);
      }
    }
  return upscale(img, scale);
}

cv::Mat heat_panel(const std::vector<float>& values, int w, int h, double vmax, int scale) {
  cv::Mat level(h, w, CV_8UC1);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const float x = values[static_cast<std::size_t>(v) * w + u];
      level.at<std::uint8_t>(v, u) =
          static_cast<std::uint8_t>(std::lround(std::clamp(x / vmax, 0.0, 1.0) * 255.0));
    }
  cv::Mat color;
  cv::applyColorMap(level, color, cv::COLORMAP_INFERNO);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      if (values[static_cast<std::size_t>(v) * w + u] < 0) color.at<cv::Vec3b>(v, u) = kEmpty;
  return upscale(color, scale);
}

std::string fmt(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// Vertical colour bar of `height` pixels, 0 at the bottom, vmax at the top.
cv::Mat color_bar(int height, double vmax) {
  const int bar_w = 18, label_w = 52;
  cv::Mat level(height, 1, CV_8UC1);
  for (int y = 0; y < height; ++y)
    level.at<std::uint8_t>(y, 0) = static_cast<std::uint8_t>(std::lround(255.0 * (height - 1 - y) / std::max(1, height - 1)));
  cv::Mat col;
  cv::applyColorMap(level, col, cv::COLORMAP_INFERNO);
  cv::Mat out(height, bar_w + label_w + 6, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat roi = out(cv::Rect(4, 0, bar_w, height));
  cv::resize(col, roi, cv::Size(bar_w, height), 0, 0, cv::INTER_NEAREST);
  for (int k = 0; k <= 4; ++k) {
    const int y = static_cast<int>(std::lround((height - 1) * (1.0 - k / 4.0)));
    cv::line(out, {4 + bar_w, y}, {4 + bar_w + 4, y}, cv::Scalar(0, 0, 0), 1);
    const int ty = std::clamp(y + 4, 10, height - 2);
    cv::putText(out, fmt(vmax * k / 4.0) + (k == 4 ? "+" : ""), {4 + bar_w + 7, ty}, cv::FONT_HERSHEY_SIMPLEX, 0.38,
                cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  return out;
}

cv::Mat titled(const cv::Mat& panel, const std::string& title) {
  const int title_h = 22;
  cv::Mat out(panel.rows + title_h, panel.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  panel.copyTo(out(cv::Rect(0, title_h, panel.cols, panel.rows)));
  cv::putText(out, title, {4, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return out;
}

cv::Mat hstack(const std::vector<cv::Mat>& parts, int gap) {
  int w = 0, h = 0;
  for (const auto& p : parts) {
    w += p.cols + gap;
    h = std::max(h, p.rows);
  }
  w -= gap;
  cv::Mat out(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  int x = 0;
  for (const auto& p : parts) {
    p.copyTo(out(cv::Rect(x, h - p.rows, p.cols, p.rows)));
    x += p.cols + gap;
  }
  return out;
}

std::vector<std::uint8_t> to_bytes(const cv::Mat& img, int* w, int* h) {
  const cv::Mat c = img.isContinuous() ? img : img.clone();
  *w = c.cols;
  *h = c.rows;
  return std::vector<std::uint8_t>(c.data, c.data + c.total() * c.elemSize());
}

cv::Mat with_headline(const cv::Mat& body, const std::string& headline) {
  const int head_h = 30;
  cv::Mat out(body.rows + head_h, body.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  body.copyTo(out(cv::Rect(0, head_h, body.cols, body.rows)));
  cv::putText(out, headline, {6, 21}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return out;
}

}  // namespace

std::vector<std::uint8_t> heat_map_with_bar(const std::vector<float>& values, int width, int height, double vmax,
                                            int scale, const std::string& title, int* out_width, int* out_height) {
  const cv::Mat panel = heat_panel(values, width, height, vmax, scale);
  const cv::Mat img = with_headline(hstack({panel, color_bar(panel.rows, vmax)}, 4), title);
  return to_bytes(img, out_width, out_height);
}

std::vector<std::uint8_t> compose_compare(const std::vector<float>& truth, const std::vector<float>& estimate,
                                          int width, int height, double error_max, int scale,
                                          const std::string& headline, int* out_width, int* out_height) {
  std::vector<float> err(truth.size(), -1.f);
  for (std::size_t i = 0; i < truth.size(); ++i)
    if (truth[i] >= 0 && estimate[i] >= 0) err[i] = std::abs(truth[i] - estimate[i]);
  const cv::Mat a = titled(gray_panel(truth, width, height, scale), "original gray");
  const cv::Mat b = titled(gray_panel(estimate, width, height, scale), "regressed gray (model)");
  const cv::Mat c = titled(heat_panel(err, width, height, error_max, scale), "|error|");
  cv::Mat bar = color_bar(c.rows - 22, error_max);
  const cv::Mat img = with_headline(hstack({a, b, c, bar}, 6), headline);
  return to_bytes(img, out_width, out_height);
}

}  // namespace sogmm::tools
