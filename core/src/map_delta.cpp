// Map deltas: cut from the journal (delta_since) and replayed on a receiver
// (apply_delta); sogmm/map_delta.hpp says why they are operations.
#include "sogmm/map_delta.hpp"

#include <algorithm>
#include <cstring>
#include <string>

#include "map_state.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"

namespace sogmm {
namespace {

constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

void fnv(std::uint64_t& h, const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * kFnvPrime;
}

// Little-endian bytes of n floats (their IEEE bits), whatever the host order.
void fnv_floats(std::uint64_t& h, const std::vector<float>& v) {
  for (float f : v) {
    std::uint32_t bits;
    std::memcpy(&bits, &f, 4);
    const unsigned char le[4] = {static_cast<unsigned char>(bits), static_cast<unsigned char>(bits >> 8),
                                 static_cast<unsigned char>(bits >> 16), static_cast<unsigned char>(bits >> 24)};
    fnv(h, le, 4);
  }
}

Error bad_delta(const std::string& why) { return Error(ErrorCode::Format, "map delta: " + why); }

// The explicit components [*next, *next + n) of the delta, advancing *next.
Gmm take(const Gmm& explicit_components, std::size_t* next, std::uint64_t n) {
  if (n > explicit_components.size() - *next)
    throw bad_delta("the steps use more explicit components than the " + std::to_string(explicit_components.size()) +
                    " it carries");
  Gmm out = detail::tail(explicit_components, *next);
  out.resize(static_cast<std::size_t>(n));
  *next += static_cast<std::size_t>(n);
  return out;
}

void require_positions(const DeltaOp& op, std::size_t n, std::size_t step, bool ascending) {
  for (std::size_t i = 0; i < op.ids.size(); ++i) {
    if (op.ids[i] >= n)
      throw bad_delta("step " + std::to_string(step) + " names component " + std::to_string(op.ids[i]) +
                      " of a map of " + std::to_string(n));
    if (ascending && i > 0 && op.ids[i] <= op.ids[i - 1])
      throw bad_delta("step " + std::to_string(step) + ": component positions are not ascending");
  }
}

// The receiver's gmm after the delta's steps, built aside.
Gmm replay(const Gmm& start, const MapDelta& d) {
  Gmm g = start;
  const Gmm& carried = d.model.gmm;
  std::size_t next = 0;
  for (std::size_t step = 0; step < d.ops.size(); ++step) {
    const DeltaOp& op = d.ops[step];
    switch (op.kind) {
      case DeltaOp::Kind::Merge: {
        Gmm batch = take(carried, &next, op.count);
        batch.support_size = op.support;
        try {
          g = g.size() == 0 ? std::move(batch) : merge(g, batch);
        } catch (const Error& e) {
          throw bad_delta("step " + std::to_string(step) + " (merge): " + e.what());
        }
        break;
      }
      case DeltaOp::Kind::Remove:
        require_positions(op, g.size(), step, true);
        g = detail::without_components(
            g, std::vector<std::size_t>(op.ids.begin(), op.ids.end()));
        break;
      case DeltaOp::Kind::Set: {
        require_positions(op, g.size(), step, false);
        const Gmm values = take(carried, &next, op.ids.size());
        for (std::size_t i = 0; i < op.ids.size(); ++i) {
          const std::size_t k = static_cast<std::size_t>(op.ids[i]);
          g.weights[k] = values.weights[i];
          std::copy_n(values.mean(i), 4, g.means.data() + 4 * k);
          std::copy_n(values.covariance(i), 16, g.covariances.data() + 16 * k);
        }
        break;
      }
      case DeltaOp::Kind::Drop: {
        require_positions(op, g.size(), step, true);
        std::vector<std::uint8_t> gone(g.size(), 0);
        for (std::uint64_t k : op.ids) gone[static_cast<std::size_t>(k)] = 1;
        Gmm kept;
        kept.support_size = g.support_size;
        for (std::size_t k = 0; k < g.size(); ++k) {
          if (gone[k]) continue;
          kept.weights.push_back(g.weights[k]);
          kept.means.insert(kept.means.end(), g.mean(k), g.mean(k) + 4);
          kept.covariances.insert(kept.covariances.end(), g.covariance(k), g.covariance(k) + 16);
        }
        g = std::move(kept);
        break;
      }
    }
  }
  if (next != carried.size())
    throw bad_delta("it carries " + std::to_string(carried.size()) + " explicit components, its steps use " +
                    std::to_string(next));
  return g;
}

}  // namespace

std::uint64_t map_digest(const Gmm& gmm, const std::string& frames_text) {
  std::uint64_t h = kFnvOffset;
  fnv_floats(h, gmm.weights);
  fnv_floats(h, gmm.means);
  fnv_floats(h, gmm.covariances);
  unsigned char le[8];
  for (int i = 0; i < 8; ++i) le[i] = static_cast<unsigned char>(gmm.support_size >> (8 * i));
  fnv(h, le, 8);
  fnv(h, frames_text.data(), frames_text.size());
  return h;
}

std::uint64_t Map::revision() const { return s_->journal.revision; }
const std::string& Map::id() const { return s_->journal.map_id; }

MapDelta Map::delta_since(std::uint64_t since) const {
  const State& s = *s_;
  const detail::Journal& j = s.journal;
  auto first = std::find_if(j.entries.begin(), j.entries.end(),
                            [&](const detail::JournalEntry& e) { return e.revision_before == since; });
  const bool current = since == j.revision;
  require(since >= j.first_revision && since <= j.revision && (current || first != j.entries.end()),
          ErrorCode::InvalidArgument,
          "map: no delta from revision " + std::to_string(since) + ": this map is at revision " +
              std::to_string(j.revision) + " and holds its changes from revision " + std::to_string(j.first_revision) +
              (since > j.revision     ? ""
               : since < j.first_revision && j.history > 0
                   ? " (it keeps the changes of its last " + std::to_string(j.history) +
                         " revisions: MapOptions::delta_history; send the whole map)"
                   : " (a relayed delta is cut only where the deltas it received start)"));
  MapDelta d;
  d.map_id = j.map_id;
  d.base_revision = since;
  d.revision = j.revision;
  d.frames_before = current ? s.frames.size() : first->frames_before;
  d.frames_from = d.frames_before > 0 ? d.frames_before - 1 : 0;
  d.frames = detail::frames_text(s.frames, static_cast<std::size_t>(d.frames_from));
  d.model = s.model;
  d.model.gmm = Gmm{};
  // The map's origin (Map::origin) travels as the model's pose, as in a map
  // file (spec/format.md 2.3.1): the steps act on components held relative
  // to it, so a receiver must hold them relative to the same origin.
  d.model.pose.reset();
  if (s.origin_fixed && !detail::is_zero(s.origin)) {
    Pose pose = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    for (int i = 0; i < 3; ++i) pose[4 * i + 3] = s.origin[i];
    d.model.pose = pose;
  }
  for (auto e = first; !current && e != j.entries.end(); ++e) {
    d.ops.insert(d.ops.end(), e->ops.begin(), e->ops.end());
    Gmm& c = d.model.gmm;
    c.weights.insert(c.weights.end(), e->components.weights.begin(), e->components.weights.end());
    c.means.insert(c.means.end(), e->components.means.begin(), e->components.means.end());
    c.covariances.insert(c.covariances.end(), e->components.covariances.begin(), e->components.covariances.end());
  }
  d.model.gmm.support_size = s.model.gmm.support_size;
  d.digest = map_digest(s.model.gmm, detail::frames_text(s.frames));
  return d;
}

void Map::apply_delta(const MapDelta& d) {
  State& s = *s_;
  detail::Journal& j = s.journal;
  const bool fresh = j.revision == 0 && s.frames.empty() && s.model.gmm.size() == 0 && j.entries.empty();
  require(fresh || d.map_id == j.map_id, ErrorCode::InvalidArgument,
          "map: the delta is for map " + d.map_id + ", this is map " + j.map_id);
  require(d.base_revision == j.revision, ErrorCode::InvalidArgument,
          "map: the delta goes from revision " + std::to_string(d.base_revision) + " to " +
              std::to_string(d.revision) + " but this map is at revision " + std::to_string(j.revision) +
              (d.base_revision < j.revision ? " (already applied, or out of order)" : " (a delta is missing)"));
  require(s.n_pending == 0, ErrorCode::InvalidArgument,
          "map: " + std::to_string(s.n_pending) + " points are pending; a receiver applies deltas only");
  if (d.revision < d.base_revision) throw bad_delta("its revision is below its base revision");
  if (d.frames_before != s.frames.size())
    throw bad_delta("it expects " + std::to_string(d.frames_before) + " frames before it, this map has " +
                    std::to_string(s.frames.size()));
  if (d.frames_from > d.frames_before) throw bad_delta("its frame lines start after the receiver's last frame");
  Origin origin{};
  if (d.model.pose) {
    const Pose& p = *d.model.pose;
    const Pose translation_only = {1, 0, 0, p[3], 0, 1, 0, p[7], 0, 0, 1, p[11], 0, 0, 0, 1};
    if (p != translation_only) throw bad_delta("its pose (the map's origin) is not a pure translation");
    origin = {p[3], p[7], p[11]};
    detail::require_origin(origin);
  }
  // A receiver that has an origin (its own inserts, a loaded map, an earlier
  // delta) takes only deltas of that origin; a fresh one adopts it.
  if (!fresh && origin != s.origin)
    throw bad_delta("it holds components relative to origin (" + std::to_string(origin[0]) + ", " +
                    std::to_string(origin[1]) + ", " + std::to_string(origin[2]) + "), this map's origin is (" +
                    std::to_string(s.origin[0]) + ", " + std::to_string(s.origin[1]) + ", " +
                    std::to_string(s.origin[2]) + ")");

  // Everything aside first; the commit below only moves.
  Model model = d.model;
  model.pose.reset();
  model.gmm = replay(s.model.gmm, d);
  if (model.gmm.size() > 0) validate(model.gmm);
  if (model.gmm.support_size != d.model.gmm.support_size)
    throw bad_delta("the support size after it is " + std::to_string(model.gmm.support_size) + ", the sender's " +
                    std::to_string(d.model.gmm.support_size));
  std::vector<FrameStats> frames(s.frames.begin(), s.frames.begin() + static_cast<std::ptrdiff_t>(d.frames_from));
  for (FrameStats& f : detail::parse_frames(d.frames, d.frames_from, kDeltaFramesKey)) frames.push_back(f);
  if (map_digest(model.gmm, detail::frames_text(frames)) != d.digest)
    throw bad_delta("the map after it differs from the sender's (digest mismatch): damaged, or a receiver whose "
                    "arithmetic differs");
  detail::Searches searches = detail::searches_of(model.gmm, s.options.index_sigmas);
  detail::JournalEntry entry;
  entry.revision_before = d.base_revision;
  entry.revision_after = d.revision;
  entry.frames_before = d.frames_before;
  entry.ops = d.ops;
  entry.components = d.model.gmm;
  j.entries.reserve(j.entries.size() + 1);

  Model world = detail::is_zero(origin) ? Model{} : detail::world_frame(model, origin);

  // Commit.
  if (model.camera.known) s.camera = model.camera.camera;
  s.origin = origin;
  s.origin_fixed = s.origin_fixed || !detail::is_zero(origin) || !frames.empty();
  s.model = std::move(model);
  s.world = std::move(world);
  s.frames = std::move(frames);
  s.marginals = std::move(searches.marginals);
  s.index = std::move(searches.index);
  ++s.revision;
  if (d.revision > d.base_revision) j.append(std::move(entry));
  j.map_id = d.map_id;
  j.revision = d.revision;
}

namespace detail {

void write_identity(Model& m, const Journal& j) {
  erase_value(m, kMapIdKey);
  erase_value(m, kMapRevisionKey);
  m.key_values.emplace_back(kMapIdKey, j.map_id);
  m.key_values.emplace_back(kMapRevisionKey, std::to_string(j.revision));
}

void read_identity(Model& m, Journal& j) {
  const std::string* id = find_value(m, kMapIdKey);
  const std::string* rev = find_value(m, kMapRevisionKey);
  if (id != nullptr && rev != nullptr) {
    const bool hex = id->size() == 32 && id->find_first_not_of("0123456789abcdef") == std::string::npos;
    const bool digits = !rev->empty() && rev->size() <= 19 && rev->find_first_not_of("0123456789") == std::string::npos;
    require(hex && digits, ErrorCode::Format,
            std::string("map: keys ") + kMapIdKey + " / " + kMapRevisionKey + " are not 32 hex digits / a count");
    j.map_id = *id;
    j.revision = j.first_revision = std::stoull(*rev);
  }
  erase_value(m, kMapIdKey);
  erase_value(m, kMapRevisionKey);
}

}  // namespace detail
}  // namespace sogmm
