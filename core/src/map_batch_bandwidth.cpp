// The bandwidths a map fits novel points and revisits with:
// MapOptions::novelty_bandwidth_scale applied in proportion to how much a
// batch pools different views, and to every revisit refit.
#include "map_state.hpp"

namespace sogmm::detail {

double same_view_share(const std::vector<PendingFrame>& pending, const PendingFrame* extra) {
  double n = 0.0, sum_sq = 0.0;
  auto add = [&](const PendingFrame& p) {
    const double k = static_cast<double>(p.xyzg.size() / 4);
    n += k;
    sum_sq += k * k;
  };
  for (const PendingFrame& p : pending) add(p);
  if (extra) add(*extra);
  return n > 0 ? sum_sq / (n * n) : 1.0;
}

double batch_bandwidth(const MapOptions& o, const std::vector<PendingFrame>& pending, const PendingFrame* extra) {
  if (!o.novelty) return o.fit.bandwidth;
  // Why the square (MapOptions::novelty_bandwidth_scale): with h the share of
  // same-view pairs, a batch of slivers of many frames (h ~ 0.1-0.2) stays
  // within 1% of the scale, while a batch that is mostly one frame's view
  // (h -> 1) is fitted at close to that frame's own bandwidth. h itself
  // raised the pooled batches to 0.74-0.76 and cost the loop's depth.
  const double h = same_view_share(pending, extra);
  const double s = o.novelty_bandwidth_scale;
  return o.fit.bandwidth * (s + (1.0 - s) * h * h);
}

double refit_bandwidth(const MapOptions& o) { return o.fit.bandwidth * o.novelty_bandwidth_scale; }

}  // namespace sogmm::detail
