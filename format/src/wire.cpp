// A verifier written from spec/format.md section 4.3 (not FlatBuffers'
// Verifier, whose rules differ between versions and leave gaps): the block
// is valid exactly when these rules hold, so every reader gives it one verdict.
#include "wire.hpp"

#include <string>

#include "container.hpp"
#include "schema.hpp"

namespace sogmm::format::detail {
namespace {

enum class Kind { Scalar, String, Table, ScalarVector, StringVector, TableVector };

struct TableType;

/// One known field: its id, what it holds and, for scalars and scalar
/// vectors, the element size in bytes.
struct Field {
  int id;
  Kind kind;
  std::uint32_t size;
  const TableType* table;  // Table and TableVector
  bool required;
};

struct TableType {
  const char* name;
  const Field* fields;
  int count;
};

constexpr Field kArrayFields[] = {
    {0, Kind::Scalar, 1, nullptr, false}, {1, Kind::Scalar, 1, nullptr, false},
    {2, Kind::Scalar, 1, nullptr, false}, {3, Kind::Scalar, 1, nullptr, false},
    {4, Kind::Scalar, 8, nullptr, false}, {5, Kind::Scalar, 8, nullptr, false},
    {6, Kind::Scalar, 8, nullptr, false}, {7, Kind::Scalar, 4, nullptr, false}};
constexpr TableType kArray{"Array", kArrayFields, 8};

constexpr Field kKeyValueFields[] = {{0, Kind::String, 0, nullptr, false}, {1, Kind::String, 0, nullptr, false}};
constexpr TableType kKeyValue{"KeyValue", kKeyValueFields, 2};

constexpr Field kFitFields[] = {
    {0, Kind::Scalar, 8, nullptr, false}, {1, Kind::Scalar, 8, nullptr, false}, {2, Kind::Scalar, 8, nullptr, false},
    {3, Kind::Scalar, 8, nullptr, false}, {4, Kind::Scalar, 4, nullptr, false}, {5, Kind::Scalar, 4, nullptr, false},
    {6, Kind::Scalar, 1, nullptr, false}, {7, Kind::Scalar, 8, nullptr, false}, {8, Kind::Scalar, 8, nullptr, false}};
constexpr TableType kFit{"FitInfo", kFitFields, 9};

constexpr Field kCameraFields[] = {
    {0, Kind::Scalar, 4, nullptr, false}, {1, Kind::Scalar, 4, nullptr, false}, {2, Kind::Scalar, 8, nullptr, false},
    {3, Kind::Scalar, 8, nullptr, false}, {4, Kind::Scalar, 8, nullptr, false}, {5, Kind::Scalar, 8, nullptr, false},
    {6, Kind::Scalar, 4, nullptr, false}, {7, Kind::Scalar, 8, nullptr, false}, {8, Kind::Scalar, 8, nullptr, false},
    {9, Kind::Scalar, 8, nullptr, false}};
constexpr TableType kCamera{"Camera", kCameraFields, 10};

constexpr Field kRootFields[] = {
    {0, Kind::Scalar, 8, nullptr, false},          {1, Kind::Scalar, 4, nullptr, false},
    {2, Kind::Scalar, 8, nullptr, false},          {3, Kind::Scalar, 1, nullptr, false},
    {4, Kind::Table, 0, &kArray, true},            {5, Kind::Table, 0, &kArray, true},
    {6, Kind::Table, 0, &kArray, true},            {7, Kind::Scalar, 8, nullptr, false},
    {8, Kind::Scalar, 8, nullptr, false},          {9, Kind::StringVector, 0, nullptr, false},
    {10, Kind::StringVector, 0, nullptr, false},   {11, Kind::Scalar, 8, nullptr, false},
    {12, Kind::Scalar, 8, nullptr, false},         {13, Kind::Table, 0, &kFit, false},
    {14, Kind::Table, 0, &kCamera, false},         {15, Kind::ScalarVector, 8, nullptr, false},
    {16, Kind::String, 0, nullptr, false},         {17, Kind::String, 0, nullptr, false},
    {18, Kind::Scalar, 8, nullptr, false},         {19, Kind::TableVector, 0, &kKeyValue, false}};
constexpr TableType kRoot{"SogmmFile", kRootFields, 20};

constexpr int kMaxDepth = 64;

class Walker {
 public:
  Walker(const std::uint8_t* buf, std::uint64_t n) : buf_(buf), n_(n) {}

  void root() {
    need(0, 8, 4, "root offset and file identifier");
    table(target(0, "root offset"), kRoot, 1);
  }

 private:
  [[noreturn]] static void bad(const std::string& what) { fail(ErrorCode::Format, "bad_metadata", what); }

  /// [pos, pos + size) lies in the block and pos is a multiple of `align`.
  void need(std::uint64_t pos, std::uint64_t size, std::uint64_t align, const char* what) const {
    if (pos > n_ || size > n_ - pos) bad(std::string(what) + " at byte " + std::to_string(pos) + " ends outside the block");
    if (pos % align != 0) bad(std::string(what) + " at byte " + std::to_string(pos) + " is not aligned to " + std::to_string(align));
  }

  /// The target of the uoffset at `pos`: non-zero, inside the block.
  std::uint64_t target(std::uint64_t pos, const char* what) const {
    need(pos, 4, 4, what);
    const std::uint32_t o = load_le<std::uint32_t>(buf_ + pos);
    if (o == 0) bad(std::string(what) + " at byte " + std::to_string(pos) + " is 0");
    const std::uint64_t t = pos + o;
    if (t >= n_) bad(std::string(what) + " at byte " + std::to_string(pos) + " points outside the block");
    return t;
  }

  void table(std::uint64_t t, const TableType& type, int depth) {
    if (depth > kMaxDepth) bad("tables nested deeper than 64");
    if (++visits_ > kMaxMetadataTables) bad("more than 100000 table visits");
    const std::string name = type.name;
    need(t, 4, 4, "table");
    const std::int64_t soffset = static_cast<std::int32_t>(load_le<std::uint32_t>(buf_ + t));
    const std::int64_t vt = static_cast<std::int64_t>(t) - soffset;
    if (vt < 0) bad(name + " vtable starts before the block");
    need(static_cast<std::uint64_t>(vt), 4, 2, "vtable");
    const std::uint32_t vsize = load_le<std::uint16_t>(buf_ + vt);
    const std::uint32_t tsize = load_le<std::uint16_t>(buf_ + vt + 2);
    if (vsize < 4 || vsize % 2 != 0) bad(name + " vtable size " + std::to_string(vsize) + " is odd or below 4");
    need(static_cast<std::uint64_t>(vt), vsize, 2, "vtable");
    if (tsize < 4) bad(name + " inline size " + std::to_string(tsize) + " is below 4");
    need(t, tsize, 4, "table");
    for (int i = 0; i < type.count; ++i) {
      const Field& f = type.fields[i];
      const std::uint32_t slot = 4 + 2 * static_cast<std::uint32_t>(f.id);
      const std::uint32_t fo = slot + 2 <= vsize ? load_le<std::uint16_t>(buf_ + vt + slot) : 0;
      if (fo == 0) {
        if (f.required) bad(name + " field " + std::to_string(f.id) + " is required but absent");
        continue;
      }
      const std::uint32_t size = f.kind == Kind::Scalar ? f.size : 4;
      if (fo < 4 || fo + size > tsize) {
        bad(name + " field " + std::to_string(f.id) + " lies outside the table's inline bytes");
      }
      const std::uint64_t at = t + fo;
      need(at, size, size, "field");
      if (f.kind != Kind::Scalar) value(target(at, "field offset"), f, depth);
    }
  }

  void value(std::uint64_t t, const Field& f, int depth) {
    switch (f.kind) {
      case Kind::Scalar: return;
      case Kind::String: return string(t);
      case Kind::Table: return table(t, *f.table, depth + 1);
      case Kind::ScalarVector: vector(t, f.size); return;
      case Kind::StringVector: {
        const std::uint64_t n = vector(t, 4);
        for (std::uint64_t i = 0; i < n; ++i) string(target(t + 4 + 4 * i, "vector element offset"));
        return;
      }
      case Kind::TableVector: {
        const std::uint64_t n = vector(t, 4);
        for (std::uint64_t i = 0; i < n; ++i) table(target(t + 4 + 4 * i, "vector element offset"), *f.table, depth + 1);
        return;
      }
    }
  }

  /// A vector of n elements of `size` bytes: its length aligned to 4, its
  /// elements aligned to their size, all inside the block. Returns n.
  std::uint64_t vector(std::uint64_t t, std::uint32_t size) const {
    need(t, 4, 4, "vector length");
    const std::uint64_t n = load_le<std::uint32_t>(buf_ + t);
    need(t + 4, n * size, size, "vector elements");  // n * size < 2^35: no overflow
    return n;
  }

  void string(std::uint64_t t) const {
    need(t, 4, 4, "string length");
    const std::uint64_t n = load_le<std::uint32_t>(buf_ + t);
    need(t + 4, n + 1, 1, "string");
    if (buf_[t + 4 + n] != 0) bad("string at byte " + std::to_string(t) + " has no NUL terminator");
  }

  const std::uint8_t* buf_;
  std::uint64_t n_;
  std::uint64_t visits_ = 0;
};

}  // namespace

void verify_wire(const std::uint8_t* block, std::uint64_t length) {
  if (length < 8 || load_le<std::uint32_t>(block + 4) != load_le<std::uint32_t>(reinterpret_cast<const std::uint8_t*>("SGMM"))) {
    fail(ErrorCode::Format, "bad_metadata", "metadata file identifier is not \"SGMM\"");
  }
  Walker(block, length).root();
}

}  // namespace sogmm::format::detail
