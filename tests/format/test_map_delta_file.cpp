// Map deltas in the container (sogmm/map_delta_file.hpp, spec/format.md
// section 2.5): bit-exact round trip, and the two readers keep apart.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "sogmm/format.hpp"
#include "sogmm/map.hpp"
#include "sogmm/map_delta.hpp"
#include "sogmm/map_delta_file.hpp"

namespace {

// A textured wall of n x n points at z = 1.5 m (no randomness needed: the
// delta only has to carry what the map fitted).
std::vector<float> wall(int n, double shift) {
  std::vector<float> p;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = shift + 0.6 * i / n - 0.3, y = 0.6 * j / n - 0.3;
      const double z = 1.5 + 0.002 * std::sin(37.0 * x + 11.0 * y);
      p.insert(p.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                         static_cast<float>(0.5 + 0.3 * std::sin(9.0 * x))});
    }
  return p;
}

std::string reason_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const sogmm::format::FormatError& e) {
    return e.reason();
  } catch (const sogmm::Error& e) {
    return std::string("error: ") + e.what();
  }
  return "accepted";
}

TEST(MapDeltaFile, RoundTripIsBitExactAndReadersKeepApart) {
  sogmm::MapOptions o;
  o.batch_size = 1000;
  o.fit.em.threads = 1;
  sogmm::Map sender(o);
  const sogmm::Pose id = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  sogmm::Map receiver;
  for (int frame = 0; frame < 3; ++frame) {
    const std::vector<float> p = wall(frame == 1 ? 20 : 40, 0.25 * frame);  // frame 1 only pends
    sender.insert_points({p.data(), p.size() / 4}, id);
    const sogmm::MapDelta d = sender.delta_since(receiver.revision());
    const std::vector<std::uint8_t> bytes = sogmm::format::delta_to_bytes(d);
    const sogmm::MapDelta back = sogmm::format::delta_from_bytes(bytes.data(), bytes.size());
    ASSERT_EQ(back.model.gmm.weights.size(), d.model.gmm.weights.size());
    // A delta of a frame that only pends carries no component: memcmp on
    // the empty vectors' null data() is undefined (UBSan), so compare only
    // what there is.
    EXPECT_TRUE(d.model.gmm.covariances.empty() ||
                std::memcmp(back.model.gmm.covariances.data(), d.model.gmm.covariances.data(),
                            d.model.gmm.covariances.size() * sizeof(float)) == 0);
    EXPECT_EQ(back.digest, d.digest);
    const sogmm::format::FileInfo info = sogmm::format::read_info(bytes.data(), bytes.size(),
                                                                  sogmm::format::ReadOptions{});
    EXPECT_EQ(info.features_required, 1u);
    EXPECT_EQ(info.format_minor, 1u);
    // A model reader refuses a delta; a delta reader refuses a model and a
    // delta cut short.
    EXPECT_EQ(reason_of([&] { sogmm::format::from_bytes(bytes.data(), bytes.size()); }), "unsupported_feature");
    std::vector<std::uint8_t> cut(bytes.begin(), bytes.end() - 5);
    EXPECT_EQ(reason_of([&] { sogmm::format::delta_from_bytes(cut.data(), cut.size()); }), "truncated");
    receiver.apply_delta(back);
    if (frame == 1) {
      EXPECT_TRUE(d.ops.empty()) << "a frame that only pends carries no component";
    }
  }
  EXPECT_EQ(receiver.model().gmm.weights, sender.model().gmm.weights);
  sender.flush();
  const std::vector<std::uint8_t> model = sogmm::format::to_bytes(sender.to_model());
  EXPECT_EQ(reason_of([&] { sogmm::format::delta_from_bytes(model.data(), model.size()); }), "not_a_delta");
}

}  // namespace
