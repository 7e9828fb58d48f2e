#include "render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace sogmm::tools {

RenderedView panel_view(const RenderedImages& images) {
  RenderedView r;
  r.width = images.width;
  r.height = images.height;
  const std::size_t n = images.depth.size();
  r.depth.assign(n, -1.f);
  r.gray.assign(n, -1.f);
  r.stddev.assign(n, -1.f);
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isnan(images.depth[i])) continue;
    r.depth[i] = images.depth[i];
    r.gray[i] = images.gray[i];
    r.stddev[i] = std::sqrt(std::max(images.variance[i], 0.f));
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

const cv::Vec3b kEmpty(70, 100, 70);  // BGR dull green: "no data" in every panel

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

// `body` below a white band `band_h` pixels high holding `text` at `at` (baseline) in a font of `scale`.
cv::Mat with_text_band(const cv::Mat& body, const std::string& text, int band_h, cv::Point at, double scale) {
  cv::Mat out(body.rows + band_h, body.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  body.copyTo(out(cv::Rect(0, band_h, body.cols, body.rows)));
  cv::putText(out, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return out;
}

cv::Mat titled(const cv::Mat& panel, const std::string& title) { return with_text_band(panel, title, 22, {4, 16}, 0.5); }

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
  return with_text_band(body, headline, 30, {6, 21}, 0.6);
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
