// Fuzz target: random sequences of map API calls (issue 36) with hostile
// frames, poses and options.
//
// The input is a program, as in fuzz_api: each step is one opcode byte and
// the bytes that step consumes (see the switch at the end). The state is two
// map slots, two options handles (the map's: fit, map and RGB-D keys; the
// queries' and saves'), one frame decoded from PNGs the step wrote, and the
// bytes of the last saved map.
//
// Invariants checked after every call (a violation aborts, which libFuzzer
// records as a crash), besides no crash, hang or sanitizer report:
// - a status is OK or a documented code with a message; INTERNAL never comes;
// - a call that creates a handle leaves *out == NULL on error;
// - a failed insert, flush or cancelled call leaves the map as it was
//   (components, pending points, frames); an OK insert records one frame;
//   discard_pending drops exactly the pending points;
// - from inside a map's progress callback, a call changing the map and
//   sogmm_map_free are refused with "map busy" (a const call too while the
//   outer call changes the map), and nothing waits;
// - every exported model is valid (finite, weights summing to 1), and the
//   map queries write bitwise what the sogmm_model_* queries write on it;
//   query outputs are in range (finite, probabilities in [0, 1]) and
//   untouched when the call fails;
// - save -> load -> save writes the same bytes (but the creation time);
// - never locked (issue 36): at the end of every input, each map's pending
//   points flush, or are discarded, and the map then saves (or is empty).
// - a declared origin is taken only by an empty map and only when every axis
//   is a finite float32; tracking records a frame exactly when it says it
//   inserted one, at a finite pose; a delta (exported since any revision,
//   sometimes with a flipped byte) brings the receiver to the sender's
//   revision and component count, or is refused with the receiver unchanged.
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../format/image_writers.hpp"
#include "fuzz_inputs.hpp"

namespace {

using sogmm_fuzz::check_created;
using sogmm_fuzz::check_model;
using sogmm_fuzz::Reader;
using sogmm_fuzz::take_double;

constexpr int kMaps = 2;
constexpr int kMaxSteps = 40;
constexpr std::size_t kMaxPoints = 160;          // points of one insert_points step
constexpr std::size_t kMaxPointsPerInput = 1200;  // all inserts of one input: keeps the fits cheap
constexpr std::uint32_t kMaxSide = 12;            // frame and render images, pixels
constexpr std::int64_t kMaxComponents = 16;       // SOGMM_OPT_N_COMPONENTS

// Map calls may also return CANCELLED and BUSY.
void check_status(sogmm_status s) { sogmm_fuzz::check_status(s, SOGMM_E_BUSY); }

// A folder of this process for the saved maps, removed at exit (the string
// is never destroyed: the exit handler runs after static destructors).
const std::string& tmp_dir() {
  static const std::string& dir = *new std::string([] {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base && *base ? base : "/tmp") + "/sogmm_fuzz_map_XXXXXX";
    FUZZ_CHECK(::mkdtemp(pattern.data()) != nullptr);
    std::atexit([] {
      for (const char* f : {"/a.sogmm", "/b.sogmm", "/c.sogmm", "/in.sogmm"}) std::remove((tmp_dir() + f).c_str());
      ::rmdir(tmp_dir().c_str());
    });
    return pattern;
  }());
  return dir;
}
std::string tmp_path(const char* name) { return tmp_dir() + "/" + name; }

std::vector<std::uint8_t> read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
void write_all(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  FUZZ_CHECK(f.good());
}

// The progress callback of a map slot: cancels at report `cancel_at` (0 =
// never) and checks the map's use guard from inside the call.
struct Progress {
  std::uint32_t cancel_at = 0;
  std::uint32_t calls = 0;
  sogmm_map* map = nullptr;   // the map whose call reports
  bool outer_writes = false;  // that call changes the map (insert, flush)
};

std::int32_t on_progress(std::int32_t stage, std::uint64_t step, std::uint64_t, double, void* user) {
  auto* p = static_cast<Progress*>(user);
  ++p->calls;
  if (std::getenv("SOGMM_FUZZ_TRACE")) std::fprintf(stderr, "  progress stage %d step %llu\n", stage, (unsigned long long)step);
  if (p->map) {
    FUZZ_CHECK(sogmm_map_flush(p->map) == SOGMM_E_BUSY);
    int64_t components = 0;
    FUZZ_CHECK(sogmm_map_get_i64(p->map, SOGMM_MAP_N_COMPONENTS, &components) ==
               (p->outer_writes ? SOGMM_E_BUSY : SOGMM_OK));
    sogmm_map_free(p->map);  // refused: the map stays valid (ASan would see a use after free)
    FUZZ_CHECK(std::strncmp(sogmm_last_error(), "map busy", 8) == 0);
  }
  return p->cancel_at != 0 && p->calls >= p->cancel_at ? 1 : 0;
}

struct Slot {
  sogmm_map* map = nullptr;
  sogmm_options* made_with = nullptr;  // a copy of the options it was created or loaded with (NULL = defaults)
  Progress progress;                   // stable address: the map's callback data
  bool has_progress = false;
};

struct State {
  std::array<Slot, kMaps> maps;
  sogmm_options* map_options = nullptr;    // create, load, inserts
  sogmm_options* query_options = nullptr;  // queries, saves
  sogmm_frame* frame = nullptr;
  std::size_t points_used = 0;
  std::vector<std::uint8_t> last_saved;
  ~State() {
    for (Slot& s : maps) {
      sogmm_map_free(s.map);
      sogmm_options_free(s.made_with);
    }
    sogmm_options_free(map_options);
    sogmm_options_free(query_options);
    sogmm_frame_free(frame);
  }
};

// The work bounds of every call-sequence target (bound_work), plus a batch
// of 256 points and at most kMaxComponents fixed components.
sogmm_options* bounded(sogmm_options*& o) {
  const bool fresh = o == nullptr;
  sogmm_fuzz::bound_work(o);
  if (fresh) FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_MAP_BATCH_SIZE, 256) == SOGMM_OK);
  std::int64_t v = 0;
  if (sogmm_options_get_i64(o, SOGMM_OPT_N_COMPONENTS, &v) == SOGMM_OK && v > kMaxComponents)
    FUZZ_CHECK(sogmm_options_set_i64(o, SOGMM_OPT_N_COMPONENTS, kMaxComponents) == SOGMM_OK);
  return o;
}

// A documented option key (by its index in the registry) or any 32-bit value.
sogmm_key take_key(Reader& in) {
  static const std::vector<sogmm_key> keys = [] {
    std::size_t n = 0;
    FUZZ_CHECK(sogmm_option_keys(nullptr, 0, &n) == SOGMM_OK);
    std::vector<sogmm_key> k(n);
    FUZZ_CHECK(sogmm_option_keys(k.data(), n, &n) == SOGMM_OK);
    return k;
  }();
  const std::uint8_t b = in.take<std::uint8_t>();
  if (b < keys.size()) return keys[b];
  return in.take<sogmm_key>();
}

// Values that break maps (issue 36): far away (500 km, UTM), beyond a batch's
// extent, beyond float32, not finite.
double take_special(Reader& in) {
  static const double special[] = {0.0,  1e-30, 0.5,  1e3,  1e5,   5e5,    1e6,  2e6,
                                   1e8,  1e10,  1e20, 1e39, 3.4e38, 1e300, NAN,  INFINITY};
  const std::uint8_t b = in.take<std::uint8_t>();
  return (b & 0x80 ? -1.0 : 1.0) * special[b % 16];
}

// A camera-to-world pose: the shared quaternion/raw pose, a translation of
// special values, a rotation by a tiny angle, or a slightly scaled
// (non-orthonormal) rotation.
std::array<double, 16> take_map_pose(Reader& in) {
  const std::uint8_t how = in.take<std::uint8_t>();
  std::array<double, 16> t = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  switch (how % 4) {
    case 0: return sogmm_fuzz::take_pose(in);
    case 1:
      for (int i = 0; i < 3; ++i) t[4 * i + 3] = (how >> (2 + i)) & 1 ? take_special(in) : take_double(in);
      return t;
    case 2: {
      const double a = std::ldexp(1.0, -static_cast<int>(in.take<std::uint8_t>() % 64));  // 1 down to 2^-63 rad
      t[0] = t[5] = std::cos(a);
      t[1] = -std::sin(a);
      t[4] = std::sin(a);
      t[3] = take_double(in);
      return t;
    }
    default: {
      const double s = 1.0 + std::ldexp(1.0, -static_cast<int>(in.take<std::uint8_t>() % 48));  // 2 down to 1 + 2^-47
      t[0] = t[5] = t[10] = s;
      t[3 + 4 * (how >> 2) % 12] = take_double(in);
      return t;
    }
  }
}

struct Counts {
  std::uint64_t components, pending, frames;
  bool operator==(const Counts& o) const {
    return components == o.components && pending == o.pending && frames == o.frames;
  }
};

Counts counts(const sogmm_map* m) {
  int64_t v[3] = {0, 0, 0};
  FUZZ_CHECK(sogmm_map_get_i64(m, SOGMM_MAP_N_COMPONENTS, &v[0]) == SOGMM_OK);
  FUZZ_CHECK(sogmm_map_get_i64(m, SOGMM_MAP_N_PENDING, &v[1]) == SOGMM_OK);
  FUZZ_CHECK(sogmm_map_get_i64(m, SOGMM_MAP_N_FRAMES, &v[2]) == SOGMM_OK);
  return {static_cast<std::uint64_t>(v[0]), static_cast<std::uint64_t>(v[1]), static_cast<std::uint64_t>(v[2])};
}

// Replaces the slot's map by `m`, made with `options` (a copy is kept: a map
// saves the options it was made with, so only the same ones load it back to
// the same bytes).
void put(Slot& slot, sogmm_map* m, const sogmm_options* options) {
  if (std::getenv("SOGMM_FUZZ_TRACE")) std::fprintf(stderr, "  -> new map\n");
  sogmm_map_free(slot.map);
  sogmm_options_free(slot.made_with);
  slot.map = m;
  slot.made_with = nullptr;
  if (m && options) FUZZ_CHECK(sogmm_options_clone(&slot.made_with, options) == SOGMM_OK);
  slot.has_progress = false;
}

// Arms the slot's callback for one call that changes the map.
void arm(Slot& slot, bool writes) {
  slot.progress.calls = 0;
  slot.progress.map = slot.map;
  slot.progress.outer_writes = writes;
}

void step_set_option(State& st, Reader& in) {
  const std::uint8_t which = in.take<std::uint8_t>();
  sogmm_options* o = bounded(which & 1 ? st.query_options : st.map_options);
  const sogmm_key key = take_key(in);
  if (which & 2) {
    check_status(sogmm_options_set_f64(o, key, which & 4 ? take_special(in) : take_double(in)));
  } else {
    const std::int64_t v = (which & 4) ? in.take<std::int64_t>() : static_cast<std::int8_t>(in.take<std::uint8_t>());
    check_status(sogmm_options_set_i64(o, key, v));
  }
}

void step_create(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const sogmm_options* o = (in.take<std::uint8_t>() & 1) ? nullptr : bounded(st.map_options);
  sogmm_map* m = reinterpret_cast<sogmm_map*>(1);
  const sogmm_status s = sogmm_map_create(&m, o);
  check_status(s);
  if (s != SOGMM_OK) {
    FUZZ_CHECK(m == nullptr);
    return;
  }
  FUZZ_CHECK(m != nullptr);
  put(slot, m, o);
  FUZZ_CHECK(counts(m) == (Counts{0, 0, 0}));
}

// An insert: refused or failed -> the map as it was; OK -> one more frame.
template <typename Insert>
void checked_insert(Slot& slot, Insert insert) {
  const Counts before = counts(slot.map);
  arm(slot, true);
  const sogmm_status s = insert();
  check_status(s);
  FUZZ_CHECK(s != SOGMM_E_BUSY);  // no other call runs
  const Counts after = counts(slot.map);
  if (s == SOGMM_OK) {
    FUZZ_CHECK(after.frames == before.frames + 1);
  } else {
    FUZZ_CHECK(after == before);
    FUZZ_CHECK(s != SOGMM_E_CANCELLED || slot.has_progress);
  }
}

void step_insert_points(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const std::size_t n = in.take<std::uint8_t>() % kMaxPoints;
  const std::vector<float> pts = sogmm_fuzz::take_points(in, n);
  const std::array<double, 16> pose = take_map_pose(in);
  if (!slot.map) {
    FUZZ_CHECK(sogmm_map_insert_points_f32(nullptr, pts.data(), n, pose.data()) == SOGMM_E_NULL_ARG);
    return;
  }
  if (st.points_used + n > kMaxPointsPerInput) return;
  st.points_used += n;
  checked_insert(slot, [&] { return sogmm_map_insert_points_f32(slot.map, pts.data(), n, pose.data()); });
}

// A frame from PNGs written here: a 16-bit depth image (0 = no depth, else
// 0.9 to 1.9 m at the default scale, or raw 16-bit values), no colour, a gray
// or an RGB image (sometimes of another size), and hostile intrinsics (or
// none).
void step_frame(State& st, Reader& in) {
  const std::uint8_t what = in.take<std::uint8_t>();
  const std::uint32_t w = 1 + in.take<std::uint8_t>() % kMaxSide, h = 1 + in.take<std::uint8_t>() % kMaxSide;
  std::vector<std::uint8_t> depth(2 * w * h), gray(w * h), rgb(3 * w * h);
  for (std::uint32_t i = 0; i < w * h; ++i) {
    const std::uint8_t b = in.take<std::uint8_t>();
    const std::uint16_t d = (what & 1) ? in.take<std::uint16_t>() : (b == 0 ? 0 : static_cast<std::uint16_t>(900 + 4 * b));
    depth[2 * i] = static_cast<std::uint8_t>(d >> 8);  // PNG samples are big-endian
    depth[2 * i + 1] = static_cast<std::uint8_t>(d & 0xff);
    gray[i] = b;
    rgb[3 * i] = b;
    rgb[3 * i + 1] = static_cast<std::uint8_t>(255 - b);
    rgb[3 * i + 2] = static_cast<std::uint8_t>(b * 7);
  }
  const std::vector<std::uint8_t> depth_png = sogmm_test::write_png(static_cast<int>(w), static_cast<int>(h), 0, 16, depth);
  std::vector<std::uint8_t> color_png;
  switch ((what >> 1) % 4) {
    case 1: color_png = sogmm_test::write_png(static_cast<int>(w), static_cast<int>(h), 0, 8, gray); break;
    case 2: color_png = sogmm_test::write_png(static_cast<int>(w), static_cast<int>(h), 2, 8, rgb); break;
    case 3: color_png = sogmm_test::write_png(static_cast<int>(w), 1, 0, 8, std::vector<std::uint8_t>(gray.begin(), gray.begin() + w)); break;
    default: break;
  }
  sogmm_frame_free(st.frame);
  st.frame = reinterpret_cast<sogmm_frame*>(1);
  const sogmm_status s = sogmm_frame_decode(&st.frame, depth_png.data(), depth_png.size(),
                                            color_png.empty() ? nullptr : color_png.data(), color_png.size());
  check_status(s);
  if (s != SOGMM_OK) {
    FUZZ_CHECK(st.frame == nullptr);
    FUZZ_CHECK((what >> 1) % 4 == 3 && h != 1);  // only the colour image of another size is refused
    return;
  }
  FUZZ_CHECK(sogmm_frame_width(st.frame) == w && sogmm_frame_height(st.frame) == h);
  if (what & 0x10) return;  // no intrinsics: inserting it is refused
  const double f = (what & 0x20) ? take_special(in) : 4.0 + (in.take<std::uint8_t>() % 32);
  const double fy = (what & 0x40) ? take_double(in) : f;
  const double c = (what & 0x80) ? take_special(in) : w / 2.0;
  check_status(sogmm_frame_set_intrinsics(st.frame, f, fy, c, h / 2.0));
}

void step_insert_frame(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const std::array<double, 16> pose = take_map_pose(in);
  if (!slot.map) return;
  const std::size_t n = st.frame ? sogmm_frame_width(st.frame) * std::size_t{sogmm_frame_height(st.frame)} : 0;
  if (st.points_used + n > kMaxPointsPerInput) return;
  st.points_used += n;
  checked_insert(slot, [&] { return sogmm_map_insert_frame(slot.map, st.frame, pose.data()); });
}

void step_flush(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  if (!slot.map) {
    FUZZ_CHECK(sogmm_map_flush(nullptr) == SOGMM_E_NULL_ARG);
    return;
  }
  const Counts before = counts(slot.map);
  arm(slot, true);
  const sogmm_status s = sogmm_map_flush(slot.map);
  check_status(s);
  const Counts after = counts(slot.map);
  if (s == SOGMM_OK) {
    FUZZ_CHECK(after.pending == 0 && after.frames == before.frames);
    FUZZ_CHECK(before.pending == 0 ? after == before : after.components >= 1);
  } else {
    FUZZ_CHECK(after == before);
    FUZZ_CHECK(s != SOGMM_E_CANCELLED || slot.has_progress);
  }
}

void step_discard(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  if (!slot.map) return;
  const Counts before = counts(slot.map);
  std::uint64_t dropped = 12345;
  FUZZ_CHECK(sogmm_map_discard_pending(slot.map, (in.take<std::uint8_t>() & 1) ? nullptr : &dropped) == SOGMM_OK);
  FUZZ_CHECK(dropped == 12345 || dropped == before.pending);
  FUZZ_CHECK(counts(slot.map) == (Counts{before.components, 0, before.frames}));
}

void step_progress(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const std::uint8_t cancel_at = in.take<std::uint8_t>();
  if (!slot.map) return;
  const bool on = cancel_at != 0xff;
  slot.progress.cancel_at = cancel_at % 16;  // 0: never cancels, only checks
  FUZZ_CHECK(sogmm_map_set_progress(slot.map, on ? on_progress : nullptr, on ? &slot.progress : nullptr) == SOGMM_OK);
  slot.has_progress = on;
}

// Equal but for the creation time (written at each save): the files'
// metadata differ only in that value's bytes and the metadata CRC.
void check_same_file(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  FUZZ_CHECK(a.size() == b.size());
  if (a == b) return;
  std::int64_t ta = 0, tb = 0;
  for (const auto* f : {&a, &b}) {
    sogmm_model* m = nullptr;
    FUZZ_CHECK(sogmm_model_load_from_memory(&m, f->data(), f->size(), nullptr) == SOGMM_OK);
    FUZZ_CHECK(sogmm_model_get_info_i64(m, SOGMM_INFO_CREATED_UNIX_MS, f == &a ? &ta : &tb) == SOGMM_OK);
    sogmm_model_free(m);
  }
  FUZZ_CHECK(ta != tb);
  std::vector<std::uint8_t> c = b;
  int replaced = 0;
  for (std::size_t i = 32; i + 8 <= c.size(); ++i)
    if (std::memcmp(&c[i], &tb, 8) == 0 && std::memcmp(&a[i], &ta, 8) == 0) {
      std::memcpy(&c[i], &ta, 8);
      ++replaced;
    }
  FUZZ_CHECK(replaced == 1);
  for (std::size_t i = 28; i < 32; ++i) c[i] = a[i];  // metadata_crc32c
  FUZZ_CHECK(a == c);
}

// The write options of a save: the query handle (hostile encodings), whose
// decoded-size cap may refuse a map (LIMIT, before anything is written).
bool save_may_fail_limit(const sogmm_options* o) {
  std::int64_t cap = 0;
  return o && sogmm_options_get_i64(o, SOGMM_OPT_MAX_DECODED_BYTES, &cap) == SOGMM_OK && cap > 0;
}

void step_save_load(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const std::uint8_t what = in.take<std::uint8_t>();
  if (!slot.map) return;
  const sogmm_options* wo = (what & 1) ? bounded(st.query_options) : nullptr;
  const Counts c = counts(slot.map);
  const std::string a = tmp_path("a.sogmm"), b = tmp_path("b.sogmm");
  std::remove(a.c_str());
  const sogmm_status s = sogmm_map_save(slot.map, a.c_str(), wo);
  check_status(s);
  if (c.pending > 0 || c.components == 0) {
    FUZZ_CHECK(s == (c.pending > 0 ? SOGMM_E_INVALID_ARG : SOGMM_E_INVALID_DATA));
    FUZZ_CHECK(::access(a.c_str(), F_OK) != 0);  // nothing written
    return;
  }
  if (s != SOGMM_OK) {
    FUZZ_CHECK(s == SOGMM_E_LIMIT && save_may_fail_limit(wo));
    return;
  }
  sogmm_map* back = reinterpret_cast<sogmm_map*>(1);
  const sogmm_status r = sogmm_map_load(&back, a.c_str(), slot.made_with);
  check_status(r);
  if (r != SOGMM_OK) {
    // Only the read cap of the options the map was made with may refuse what the library wrote.
    FUZZ_CHECK(back == nullptr && r == SOGMM_E_LIMIT && save_may_fail_limit(slot.made_with));
    return;
  }
  FUZZ_CHECK(counts(back) == (Counts{c.components, 0, c.frames}));
  const sogmm_status s2 = sogmm_map_save(back, b.c_str(), wo);
  FUZZ_CHECK(s2 == SOGMM_OK);
  st.last_saved = read_all(a);
  check_same_file(st.last_saved, read_all(b));
  if (what & 2) {
    Slot& other = st.maps[(&slot - st.maps.data() + 1) % kMaps];
    if (&other != &slot) put(other, back, slot.made_with);
  } else {
    sogmm_map_free(back);
  }
}

void step_load_bytes(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const std::uint8_t what = in.take<std::uint8_t>();
  std::vector<std::uint8_t> bytes;
  if (!st.last_saved.empty() && (what & 1)) {
    bytes = st.last_saved;  // with a few bytes flipped, or truncated
    for (int r = 0; r < 1 + (what >> 1) % 4; ++r) {
      const std::uint16_t at = in.take<std::uint16_t>();
      bytes[at % bytes.size()] ^= in.take<std::uint8_t>() | 1;
    }
    if (what & 0x20) bytes.resize(in.take<std::uint16_t>() % bytes.size());
  } else {
    const std::size_t len = in.take<std::uint8_t>();
    for (std::size_t i = 0; i < len; ++i) bytes.push_back(in.take<std::uint8_t>());
  }
  const std::string path = tmp_path("in.sogmm");
  write_all(path, bytes);
  sogmm_map* m = reinterpret_cast<sogmm_map*>(1);
  const sogmm_options* o = (what & 0x40) ? nullptr : bounded(st.map_options);
  const sogmm_status s = sogmm_map_load(&m, path.c_str(), o);
  check_status(s);
  if (s != SOGMM_OK) {
    FUZZ_CHECK(m == nullptr);
    return;
  }
  const Counts c = counts(m);
  FUZZ_CHECK(c.components >= 1 && c.pending == 0);
  put(slot, m, o);
}

// Query outputs start as this value: a failed call must leave them so.
constexpr float kUntouchedF = 12345.0f;
constexpr double kUntouchedD = 12345.0;

template <typename T>
void check_untouched(const std::vector<T>& v, T sentinel) {
  for (T x : v) FUZZ_CHECK(std::memcmp(&x, &sentinel, sizeof x) == 0);
}

// Points near the map (the tame cloud), or anywhere the input says.
std::vector<float> take_xyz(Reader& in, std::size_t n) {
  const std::vector<float> p = sogmm_fuzz::take_points(in, n);
  std::vector<float> xyz(3 * n + 3);
  for (std::size_t i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) xyz[3 * i + j] = p[4 * i + j];
  return xyz;
}

void step_query(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const std::uint8_t what = in.take<std::uint8_t>();
  const std::size_t n = in.take<std::uint8_t>() % 64;
  if (!slot.map) return;
  const sogmm_map* map = slot.map;
  // The queries' options, sometimes with a callback that cancels and checks the guard.
  sogmm_options* o = bounded(st.query_options);
  Progress progress;
  progress.cancel_at = (what >> 4) % 4;
  progress.map = slot.map;
  FUZZ_CHECK(sogmm_options_set_progress(o, (what & 8) ? on_progress : nullptr, &progress) == SOGMM_OK);
  const bool may_cancel = (what & 8) && progress.cancel_at != 0;
  const std::uint64_t components = counts(map).components;
  sogmm_model* exported = nullptr;
  if (components > 0) FUZZ_CHECK(sogmm_map_export(&exported, map, nullptr) == SOGMM_OK);
  auto ok = [&](sogmm_status s) {
    check_status(s);
    // An empty map is refused but by occupancy, which answers "unknown".
    if (components == 0 && s == SOGMM_OK) FUZZ_CHECK((what % 8) >= 5);
    if (s == SOGMM_E_CANCELLED) FUZZ_CHECK(may_cancel);
    return s == SOGMM_OK;
  };
  switch (what % 8) {
    case 0: {
      float box[6];
      for (int i = 0; i < 3; ++i) {
        box[i] = sogmm_fuzz::take_float(in);
        box[3 + i] = box[i] + std::fabs(sogmm_fuzz::take_float(in));
      }
      sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
      const sogmm_status s = sogmm_map_export(&m, map, (what & 0x40) ? nullptr : box);
      check_created(s, m, SOGMM_E_BUSY);
      if (s == SOGMM_OK) {
        std::size_t k = 0;
        FUZZ_CHECK(sogmm_model_n_components(m, &k) == SOGMM_OK && k <= components);
      }
      sogmm_model_free(m);
      break;
    }
    case 1: {
      const int32_t dims = (what & 0x40) ? 3 : 4;
      const std::vector<float> pts = sogmm_fuzz::take_points(in, n);
      std::vector<double> out(n + 1, kUntouchedD), want(n + 1, kUntouchedD);
      if (ok(sogmm_map_score_samples_f32(map, pts.data(), n, dims, o, out.data()))) {
        FUZZ_CHECK(sogmm_options_set_progress(o, nullptr, nullptr) == SOGMM_OK);
        FUZZ_CHECK(sogmm_model_score_samples_f32(exported, pts.data(), n, dims, o, want.data()) == SOGMM_OK);
        FUZZ_CHECK(std::memcmp(out.data(), want.data(), n * sizeof(double)) == 0);
        for (std::size_t i = 0; i < n; ++i) FUZZ_CHECK(!std::isnan(out[i]) && out[i] != INFINITY);
      } else {
        check_untouched(out, kUntouchedD);
      }
      break;
    }
    case 2: {
      const std::vector<float> xyz = take_xyz(in, n);
      std::vector<float> mean(n + 1, kUntouchedF), var(n + 1, kUntouchedF), want(2 * n + 2, kUntouchedF);
      if (ok(sogmm_map_regress_gray_f32(map, xyz.data(), n, o, mean.data(), var.data()))) {
        for (std::size_t i = 0; i < n; ++i) FUZZ_CHECK(std::isfinite(mean[i]) && var[i] >= 0);
        FUZZ_CHECK(sogmm_options_set_progress(o, nullptr, nullptr) == SOGMM_OK);
        FUZZ_CHECK(sogmm_model_regress_gray_f32(exported, xyz.data(), n, o, want.data(), want.data() + n + 1) ==
                   SOGMM_OK);
        FUZZ_CHECK(std::memcmp(mean.data(), want.data(), n * sizeof(float)) == 0);
        FUZZ_CHECK(std::memcmp(var.data(), want.data() + n + 1, n * sizeof(float)) == 0);
      } else {
        check_untouched(mean, kUntouchedF);
      }
      break;
    }
    case 3: {
      const int32_t dims = (what & 0x40) ? 3 : 4;
      const std::uint64_t seed = in.take<std::uint64_t>();
      std::vector<float> out(4 * n + 4, kUntouchedF), want(4 * n + 4, kUntouchedF);
      if (ok(sogmm_map_sample_f32(map, n, seed, dims, o, out.data()))) {
        for (std::size_t i = 0; i < n * dims; ++i) FUZZ_CHECK(std::isfinite(out[i]));
        FUZZ_CHECK(sogmm_options_set_progress(o, nullptr, nullptr) == SOGMM_OK);
        FUZZ_CHECK(sogmm_model_sample_f32(exported, n, seed, dims, o, want.data()) == SOGMM_OK);
        FUZZ_CHECK(std::memcmp(out.data(), want.data(), n * dims * sizeof(float)) == 0);
      } else {
        check_untouched(out, kUntouchedF);
      }
      break;
    }
    case 4: {
      const std::uint32_t w = 1 + in.take<std::uint8_t>() % kMaxSide, h = 1 + in.take<std::uint8_t>() % kMaxSide;
      const double f = (what & 0x40) ? take_double(in) : 10.0;
      const std::array<double, 16> pose = take_map_pose(in);
      std::vector<float> depth(w * h, kUntouchedF), gray(w * h, kUntouchedF), var(w * h, kUntouchedF);
      if (ok(sogmm_map_render_f32(map, w, h, f, f, w / 2.0, h / 2.0, (what & 0x80) ? nullptr : pose.data(), o,
                                  depth.data(), gray.data(), var.data()))) {
        for (std::size_t i = 0; i < depth.size(); ++i) {
          FUZZ_CHECK(std::isnan(depth[i]) == std::isnan(gray[i]) && std::isnan(gray[i]) == std::isnan(var[i]));
          FUZZ_CHECK(std::isnan(depth[i]) || (std::isfinite(depth[i]) && std::isfinite(gray[i]) && var[i] >= 0));
        }
      } else {
        check_untouched(depth, kUntouchedF);
      }
      break;
    }
    case 5: {
      const std::vector<float> xyz = take_xyz(in, n);
      std::vector<double> p(n + 1, kUntouchedD);
      std::vector<std::uint8_t> state(n + 1, 77);
      if (ok(sogmm_map_occupancy_f32(map, xyz.data(), n, o, p.data(), state.data()))) {
        for (std::size_t i = 0; i < n; ++i) FUZZ_CHECK(p[i] >= 0 && p[i] <= 1 && state[i] <= SOGMM_OCCUPANCY_UNKNOWN);
      } else {
        check_untouched(p, kUntouchedD);
      }
      break;
    }
    case 6: {
      const std::vector<float> xyz = take_xyz(in, n);
      std::vector<double> d(n + 1, kUntouchedD), g(3 * n + 3, kUntouchedD);
      if (ok(sogmm_map_surface_distance_f32(map, xyz.data(), n, o, d.data(), g.data()))) {
        for (std::size_t i = 0; i < n; ++i) FUZZ_CHECK(std::isfinite(d[i]) && d[i] >= 0);
        for (std::size_t i = 0; i < 3 * n; ++i) FUZZ_CHECK(std::isfinite(g[i]));
      } else {
        check_untouched(d, kUntouchedD);
      }
      break;
    }
    default: {
      const std::size_t robots = n % 8;
      std::vector<double> centers(3 * robots + 3), shapes(9 * robots + 9), out(robots + 1, kUntouchedD);
      for (std::size_t i = 0; i < robots; ++i) {
        for (int j = 0; j < 3; ++j) centers[3 * i + j] = take_double(in);
        const double r = take_double(in);
        for (int j = 0; j < 3; ++j) shapes[9 * i + 4 * j] = r;  // r I: SPD when r > 0
        if (what & 0x40) shapes[9 * i + 1] = take_double(in);  // and maybe not symmetric
      }
      if (ok(sogmm_map_collision_probability(map, centers.data(), shapes.data(), robots, o, out.data()))) {
        for (std::size_t i = 0; i < robots; ++i) FUZZ_CHECK(out[i] >= 0 && out[i] <= 1);
      } else {
        check_untouched(out, kUntouchedD);
      }
    }
  }
  FUZZ_CHECK(sogmm_options_set_progress(o, nullptr, nullptr) == SOGMM_OK);
  if (exported) check_model(exported);
  sogmm_model_free(exported);
}

void step_misc(State& st, Reader& in) {
  const std::uint8_t what = in.take<std::uint8_t>();
  Slot& slot = st.maps[what % kMaps];
  switch ((what >> 1) % 3) {
    case 0: put(slot, nullptr, nullptr); break;
    case 1: {
      if (!slot.map) break;
      const std::uint64_t frame = in.take<std::uint8_t>();
      int64_t points = -1, novel = -1, replaced = -1;
      const sogmm_status s = sogmm_map_frame_get_i64(slot.map, frame, SOGMM_MAP_FRAME_N_POINTS, &points);
      check_status(s);
      FUZZ_CHECK((s == SOGMM_OK) == (frame < counts(slot.map).frames));
      FUZZ_CHECK(sogmm_map_frame_get_i64(slot.map, frame, SOGMM_MAP_FRAME_N_NOVEL, &novel) == s);
      FUZZ_CHECK(sogmm_map_frame_get_i64(slot.map, frame, SOGMM_MAP_FRAME_N_REPLACED, &replaced) == s);
      if (s == SOGMM_OK) FUZZ_CHECK(0 <= novel && novel <= points && replaced >= 0);
      break;
    }
    default:
      if (st.frame)
        check_status(sogmm_frame_set_intrinsics(st.frame, take_double(in), take_double(in), take_double(in),
                                                take_double(in)));
  }
}

std::int64_t revision(const sogmm_map* m) {
  int64_t r = -1;
  FUZZ_CHECK(sogmm_map_get_i64(m, SOGMM_MAP_REVISION, &r) == SOGMM_OK && r >= 0);
  return r;
}

// A declared origin: accepted only on a map with no frame and no component,
// and only when every axis is finite and within float32 range; a refused
// call leaves the origin as it was.
void step_origin(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  double origin[3];
  for (double& v : origin) v = (in.take<std::uint8_t>() & 1) ? take_special(in) : take_double(in);
  if (!slot.map) return;
  double before[3], after[3];
  FUZZ_CHECK(sogmm_map_get_origin(slot.map, before) == SOGMM_OK);
  const Counts c = counts(slot.map);
  const sogmm_status s = sogmm_map_set_origin(slot.map, origin);
  check_status(s);
  FUZZ_CHECK(sogmm_map_get_origin(slot.map, after) == SOGMM_OK);
  bool representable = true;
  for (double v : origin) representable = representable && std::isfinite(v) && std::fabs(v) <= 3.4028234663852886e38;
  if (s == SOGMM_OK) {
    FUZZ_CHECK(c.frames == 0 && c.components == 0 && representable);
    FUZZ_CHECK(std::memcmp(after, origin, sizeof origin) == 0);
  } else {
    FUZZ_CHECK(std::memcmp(after, before, sizeof before) == 0);
  }
}

// Tracking (issue 32) on the current frame, from a hostile guess or the
// constant-velocity prediction: a frame is recorded exactly when the call
// says it was inserted, at a finite rigid pose; an error records nothing.
void step_track(State& st, Reader& in) {
  Slot& slot = st.maps[in.take<std::uint8_t>() % kMaps];
  const std::uint8_t how = in.take<std::uint8_t>();
  const std::array<double, 16> guess = take_map_pose(in);
  if (!slot.map || !st.frame) return;
  const std::size_t n = sogmm_frame_width(st.frame) * std::size_t{sogmm_frame_height(st.frame)};
  if (st.points_used + n > kMaxPointsPerInput) return;
  st.points_used += n;
  const Counts before = counts(slot.map);
  double pose[16];
  std::int32_t inserted = -1;
  sogmm_registration_info info{};
  info.struct_size = (how & 2) ? sizeof info : in.take<std::uint8_t>();
  arm(slot, true);
  const sogmm_status s =
      sogmm_map_track_frame(slot.map, st.frame, (how & 1) ? guess.data() : nullptr, pose, &inserted, &info);
  check_status(s);
  FUZZ_CHECK(s != SOGMM_E_BUSY);
  const Counts after = counts(slot.map);
  if (s != SOGMM_OK) {
    FUZZ_CHECK(after.frames == before.frames);
    FUZZ_CHECK(s != SOGMM_E_CANCELLED || slot.has_progress);
    return;
  }
  FUZZ_CHECK(inserted == 0 || inserted == 1);
  FUZZ_CHECK(after.frames == before.frames + static_cast<std::uint64_t>(inserted));
  if (inserted)
    for (double v : pose) FUZZ_CHECK(std::isfinite(v));
}

// A delta of one slot since a revision (its first, its last, or any),
// applied to the other slot (or itself): the receiver either reaches the
// sender's revision with the sender's component count, or refuses and is
// unchanged.
void step_delta(State& st, Reader& in) {
  const std::uint8_t what = in.take<std::uint8_t>();
  Slot& from = st.maps[what % kMaps];
  Slot& to = st.maps[(what >> 1) % kMaps];
  const std::uint64_t pick = in.take<std::uint8_t>();
  if (!from.map) return;
  const std::int64_t head = revision(from.map);
  const std::uint64_t since = pick < 0x80 ? 0 : pick < 0xC0 ? static_cast<std::uint64_t>(head) : pick - 0xC0;
  std::size_t size = 0;
  const sogmm_status q = sogmm_map_export_delta(from.map, since, nullptr, nullptr, 0, &size);
  check_status(q);
  if (q != SOGMM_OK) {
    FUZZ_CHECK(q == SOGMM_E_INVALID_ARG || q == SOGMM_E_LIMIT);
    return;
  }
  FUZZ_CHECK(size > 0 && size < (std::size_t{64} << 20));
  std::vector<std::uint8_t> bytes(size);
  std::size_t written = 0;
  FUZZ_CHECK(sogmm_map_export_delta(from.map, since, nullptr, bytes.data(), bytes.size(), &written) == SOGMM_OK);
  FUZZ_CHECK(written == size);
  if (what & 4) bytes[in.take<std::uint16_t>() % bytes.size()] ^= static_cast<std::uint8_t>(1 + in.take<std::uint8_t>() % 255);
  if (!to.map) return;
  const Counts before = counts(to.map);
  const std::int64_t to_revision = revision(to.map);
  arm(to, true);
  const sogmm_status s = sogmm_map_apply_delta(to.map, bytes.data(), bytes.size(), nullptr);
  check_status(s);
  FUZZ_CHECK(s != SOGMM_E_BUSY);
  if (s == SOGMM_OK) {
    FUZZ_CHECK(revision(to.map) == head);
    FUZZ_CHECK(counts(to.map).components == counts(from.map).components);
  } else {
    FUZZ_CHECK(counts(to.map) == before && revision(to.map) == to_revision);
  }
}

// Issue 36's rule: whatever came before, a map's pending points either flush
// or are discarded, and then the map saves (or is empty and says so).
void check_never_locked(Slot& slot) {
  if (!slot.map) return;
  FUZZ_CHECK(sogmm_map_set_progress(slot.map, nullptr, nullptr) == SOGMM_OK);
  const sogmm_status f = sogmm_map_flush(slot.map);
  check_status(f);
  // An insert commits only points a flush can fit (issue 36). Left: a
  // numeric failure of EM, and with a fixed K fewer than K points pending
  // (an insert refuses only a fit it triggers); discard_pending is the way out.
  std::int64_t k = 0;
  const bool fixed_k_above_pending =
      f == SOGMM_E_INVALID_ARG &&
      sogmm_options_get_i64(slot.made_with, SOGMM_OPT_N_COMPONENTS, &k) == SOGMM_OK &&
      static_cast<std::uint64_t>(k) > counts(slot.map).pending;
  FUZZ_CHECK(f == SOGMM_OK || f == SOGMM_E_NUMERIC || fixed_k_above_pending);
  if (f != SOGMM_OK) FUZZ_CHECK(sogmm_map_discard_pending(slot.map, nullptr) == SOGMM_OK);
  const Counts c = counts(slot.map);
  FUZZ_CHECK(c.pending == 0);
  const std::string path = tmp_path("c.sogmm");
  const sogmm_status s = sogmm_map_save(slot.map, path.c_str(), nullptr);
  check_status(s);
  FUZZ_CHECK(s == (c.components > 0 ? SOGMM_OK : SOGMM_E_INVALID_DATA));
  if (c.components > 0) {
    sogmm_model* m = nullptr;
    FUZZ_CHECK(sogmm_map_export(&m, slot.map, nullptr) == SOGMM_OK);
    check_model(m);
    sogmm_model_free(m);
  }
}

// After every step: every map answers its statistics (its use guard was released).
void check_stats(const State& st) {
  for (const Slot& s : st.maps)
    if (s.map) counts(s.map);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const sogmm_fuzz::Step<State> steps[] = {
      {"set_option", step_set_option}, {"create", step_create},       {"insert_points", step_insert_points},
      {"frame", step_frame},           {"insert_frame", step_insert_frame}, {"flush", step_flush},
      {"discard", step_discard},       {"progress", step_progress},   {"save_load", step_save_load},
      {"load_bytes", step_load_bytes}, {"query", step_query},         {"misc", step_misc},
      {"origin", step_origin},         {"track", step_track},         {"delta", step_delta}};
  Reader in(data, size);
  State st;
  sogmm_fuzz::run_program(in, st, kMaxSteps, steps, check_stats);
  for (Slot& s : st.maps) check_never_locked(s);
  return 0;
}
