// The journal of a map's changes (map_journal.hpp).
#include "map_journal.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <random>

namespace sogmm::detail {

void Journal::add_components(const Gmm& gmm, std::size_t first, std::size_t n) {
  Gmm& c = open_components;
  c.weights.insert(c.weights.end(), gmm.weights.begin() + first, gmm.weights.begin() + first + n);
  c.means.insert(c.means.end(), gmm.means.begin() + 4 * first, gmm.means.begin() + 4 * (first + n));
  c.covariances.insert(c.covariances.end(), gmm.covariances.begin() + 16 * first,
                       gmm.covariances.begin() + 16 * (first + n));
}

void Journal::merge(const Gmm& batch) {
  DeltaOp op;
  op.kind = DeltaOp::Kind::Merge;
  op.count = batch.size();
  op.support = batch.support_size;
  add_components(batch, 0, batch.size());
  open_ops.push_back(std::move(op));
}

void Journal::remove(const std::vector<std::size_t>& ids) {
  if (ids.empty()) return;
  DeltaOp op;
  op.kind = DeltaOp::Kind::Remove;
  op.ids.assign(ids.begin(), ids.end());
  open_ops.push_back(std::move(op));
}

void Journal::set(const Gmm& gmm, const std::vector<std::size_t>& ids) {
  if (ids.empty()) return;
  DeltaOp op;
  op.kind = DeltaOp::Kind::Set;
  op.ids.assign(ids.begin(), ids.end());
  for (std::size_t k : ids) add_components(gmm, k, 1);
  open_ops.push_back(std::move(op));
}

void Journal::drop(const std::vector<std::size_t>& ids) {
  if (ids.empty()) return;
  DeltaOp op;
  op.kind = DeltaOp::Kind::Drop;
  op.ids.assign(ids.begin(), ids.end());
  open_ops.push_back(std::move(op));
}

Gmm tail(const Gmm& gmm, std::size_t first) {
  Gmm out;
  out.weights.assign(gmm.weights.begin() + first, gmm.weights.end());
  out.means.assign(gmm.means.begin() + 4 * first, gmm.means.end());
  out.covariances.assign(gmm.covariances.begin() + 16 * first, gmm.covariances.end());
  return out;
}

namespace {
bool same_bytes(const Gmm& a, std::size_t i, const Gmm& b, std::size_t j) {
  return std::memcmp(&a.weights[i], &b.weights[j], sizeof(float)) == 0 &&
         std::memcmp(a.mean(i), b.mean(j), 4 * sizeof(float)) == 0 &&
         std::memcmp(a.covariance(i), b.covariance(j), 16 * sizeof(float)) == 0;
}
}  // namespace

std::vector<std::size_t> dropped_positions(const Gmm& appended, const Gmm& after, std::size_t first) {
  std::vector<std::size_t> dropped;
  std::size_t kept = first;
  for (std::size_t j = 0; j < appended.size(); ++j) {
    if (kept < after.size() && same_bytes(appended, j, after, kept)) {
      ++kept;
    } else {
      dropped.push_back(first + j);
    }
  }
  return dropped;
}

std::string new_map_id() {
  // An identity, not a secret: two robots' maps must differ, and the
  // random device gives that without a clock or a configured name.
  std::random_device rd;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%08x%08x%08x%08x", static_cast<unsigned>(rd()), static_cast<unsigned>(rd()),
                static_cast<unsigned>(rd()), static_cast<unsigned>(rd()));
  return buf;
}

JournalScope::JournalScope(Journal& journal, std::size_t n_frames) : j_(journal) {
  if (j_.depth++ > 0) return;
  j_.open_ops.clear();
  j_.open_components = Gmm{};
  j_.open_frames_before = n_frames;
}

JournalScope::~JournalScope() {
  if (done_) return;
  if (--j_.depth == 0) {
    j_.open_ops.clear();
    j_.open_components = Gmm{};
  }
}

void JournalScope::commit(std::size_t n_frames) {
  done_ = true;
  if (--j_.depth > 0) return;
  if (j_.open_ops.empty() && n_frames == j_.open_frames_before) return;
  JournalEntry e;
  e.revision_before = j_.revision;
  e.revision_after = j_.revision + 1;
  e.frames_before = j_.open_frames_before;
  e.ops = std::move(j_.open_ops);
  e.components = std::move(j_.open_components);
  j_.entries.push_back(std::move(e));
  ++j_.revision;
  j_.open_ops.clear();
  j_.open_components = Gmm{};
}

}  // namespace sogmm::detail
