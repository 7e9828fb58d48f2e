// The occupancy picture of `sogmm render --occupancy` (occupancy_slice.hpp).
#include "occupancy_slice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "image_io.hpp"
#include "render.hpp"
#include "sogmm/error.hpp"
#include "sogmm/occupancy.hpp"

namespace sogmm::tools {

namespace {

// The world axis the cameras' up (-y of the camera, the image's up) points
// along most, over the map's frames.
int up_axis(const std::vector<FrameStats>& frames) {
  double up[3] = {0, 0, 0};
  for (const FrameStats& f : frames)
    for (int i = 0; i < 3; ++i) up[i] -= f.pose[4 * i + 1];
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(up[i]) > std::abs(up[best])) best = i;
  return best;
}

// BGR of a cell: free light green, occupied red, unknown mid gray, each
// lighter the less sure (P(occupied) near 0.5).
cv::Vec3b cell_color(double p, std::uint8_t state) {
  if (state == static_cast<std::uint8_t>(OccupancyState::Unknown)) return {128, 128, 128};
  const double sure = std::clamp(std::abs(p - 0.5) * 2, 0.0, 1.0);
  const cv::Vec3d pale(235, 235, 235);
  const cv::Vec3d full = state == static_cast<std::uint8_t>(OccupancyState::Occupied) ? cv::Vec3d(40, 40, 200)
                                                                                        : cv::Vec3d(170, 230, 170);
  const cv::Vec3d c = pale + sure * (full - pale);
  return {static_cast<std::uint8_t>(c[0]), static_cast<std::uint8_t>(c[1]), static_cast<std::uint8_t>(c[2])};
}

cv::Mat with_title(const cv::Mat& panel, const std::string& title) {
  const int title_h = 22;
  cv::Mat out(panel.rows + title_h, std::max(panel.cols, 8 * static_cast<int>(title.size())), CV_8UC3,
              cv::Scalar(255, 255, 255));
  panel.copyTo(out(cv::Rect(0, title_h, panel.cols, panel.rows)));
  cv::putText(out, title, {4, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return out;
}

}  // namespace

void write_occupancy_picture(const Map& map, const SliceFlags& flags, const std::string& output,
                             const std::string& map_name) {
  const std::vector<FrameStats>& frames = map.frames();
  require(!frames.empty() && map.size() > 0 && map.model().camera.known, ErrorCode::InvalidArgument,
          "render --occupancy: " + map_name + " records no RGB-D frame (a map from `sogmm map` does)");
  require(flags.frame >= 0 && static_cast<std::size_t>(flags.frame) < frames.size(), ErrorCode::InvalidArgument,
          "render --occupancy: --frame must be in [0, " + std::to_string(frames.size()) + ")");
  require(std::isfinite(flags.cell) && flags.cell > 0, ErrorCode::InvalidArgument,
          "render --occupancy: --cell must be > 0");
  int axis = up_axis(frames);
  if (!flags.axis.empty()) {
    require(flags.axis == "x" || flags.axis == "y" || flags.axis == "z", ErrorCode::InvalidArgument,
            "render --occupancy: --slice-axis must be x, y or z (got " + flags.axis + ")");
    axis = flags.axis[0] - 'x';
  }
  double height = flags.height;
  if (std::isnan(height)) {
    height = 0;
    for (const FrameStats& f : frames) height += f.pose[4 * axis + 3] / static_cast<double>(frames.size());
  }
  require(std::isfinite(height), ErrorCode::InvalidArgument, "render --occupancy: --slice-at must be finite");

  // The slice's extent: the component means in the two other axes, plus 10%.
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  const Gmm& gmm = map.model().gmm;
  double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
  for (std::size_t m = 0; m < gmm.size(); ++m)
    for (int k = 0; k < 2; ++k) {
      const double v = gmm.mean(m)[k == 0 ? a : b];
      lo[k] = std::min(lo[k], v);
      hi[k] = std::max(hi[k], v);
    }
  double cell = flags.cell;
  for (int k = 0; k < 2; ++k) {
    const double pad = 0.1 * (hi[k] - lo[k]) + cell;
    lo[k] -= pad;
    hi[k] += pad;
    cell = std::max(cell, (hi[k] - lo[k]) / 1024);
  }
  const int cols = static_cast<int>(std::ceil((hi[0] - lo[0]) / cell));
  const int rows = static_cast<int>(std::ceil((hi[1] - lo[1]) / cell));
  std::vector<float> xyz(3 * static_cast<std::size_t>(cols) * rows);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      float* x = &xyz[3 * (static_cast<std::size_t>(r) * cols + c)];
      x[axis] = static_cast<float>(height);
      x[a] = static_cast<float>(lo[0] + (c + 0.5) * cell);
      x[b] = static_cast<float>(hi[1] - (r + 0.5) * cell);  // row 0 at the top: b grows upwards
    }
  const std::size_t n = xyz.size() / 3;
  std::vector<double> p(n);
  std::vector<std::uint8_t> state(n);
  occupancy(map, xyz.data(), n, p.data(), state.data(), {}, flags.threads);
  std::size_t count[3] = {0, 0, 0};
  cv::Mat slice(rows, cols, CV_8UC3);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const std::size_t i = static_cast<std::size_t>(r) * cols + c;
      ++count[state[i]];
      slice.at<cv::Vec3b>(r, c) = cell_color(p[i], state[i]);
    }

  // Beside it: the expected surface the map shows from the frame.
  const CameraInfo& info = map.model().camera;
  RenderOptions ro;
  ro.depth_min = info.depth_min;
  ro.depth_max = info.depth_max;
  ro.threads = flags.threads;
  const RenderedView view =
      panel_view(render(gmm, decimated(info.camera, info.decimation), frames[static_cast<std::size_t>(flags.frame)].pose, ro));
  const std::vector<std::uint8_t> g = gray_to_u8(view.gray);
  cv::Mat gray_img(view.height, view.width, CV_8UC1, const_cast<std::uint8_t*>(g.data()));
  cv::Mat view_img;
  cv::cvtColor(gray_img, view_img, cv::COLOR_GRAY2BGR);
  // Both panels about 480 pixels tall.
  const auto fit = [](const cv::Mat& m) {
    const int scale = std::max(1, 480 / std::max(1, m.rows));
    cv::Mat out;
    cv::resize(m, out, cv::Size(m.cols * scale, m.rows * scale), 0, 0, cv::INTER_NEAREST);
    return out;
  };
  const char* names = "xyz";
  char title[160];
  std::snprintf(title, sizeof title, "%c = %.3f m: free (green), occupied (red), unknown (gray); %c right, %c up",
                names[axis], height, names[a], names[b]);
  const cv::Mat left = with_title(fit(slice), title);
  std::snprintf(title, sizeof title, "expected surface from frame %d", flags.frame);
  const cv::Mat right = with_title(fit(view_img), title);
  const int gap = 8, w = left.cols + gap + right.cols, h = std::max(left.rows, right.rows);
  cv::Mat out(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  left.copyTo(out(cv::Rect(0, 0, left.cols, left.rows)));
  right.copyTo(out(cv::Rect(left.cols + gap, 0, right.cols, right.rows)));
  write_png(output, out.cols, out.rows, 3, out.ptr());
  std::printf("Wrote %s (%dx%d): occupancy of %s on the plane %c = %.3f m (%dx%d cells of %.3g m: %.1f%% free, "
              "%.1f%% occupied, %.1f%% unknown) beside the expected surface from frame %d.\n",
              output.c_str(), out.cols, out.rows, map_name.c_str(), names[axis], height, cols, rows, cell,
              100.0 * count[0] / n, 100.0 * count[1] / n, 100.0 * count[2] / n, flags.frame);
}

}  // namespace sogmm::tools
