// Model <-> FlatBuffers metadata, and the metadata checks.
#include "schema.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "checks.hpp"
#include "codec.hpp"
#include "quantized_components.hpp"
#include "wire.hpp"
#include "sogmm/checked.hpp"
#include "sogmm/metadata_string.hpp"
#include "sogmm_generated.h"

namespace sogmm::format::detail {
namespace {

namespace fb = sogmm::fb;
const ErrorCode F = ErrorCode::Format;

const std::vector<std::string> kAxisLabels = {"x", "y", "z", "gray"};
const std::vector<std::string> kAxisUnits = {"m", "m", "m", "1"};

flatbuffers::Offset<fb::Array> build_array(flatbuffers::FlatBufferBuilder& b, const ArrayRecord& r) {
  return fb::CreateArray(b, static_cast<fb::DType>(r.dtype), static_cast<fb::ElementOrder>(r.order),
                         static_cast<fb::Filter>(r.filter), static_cast<fb::Codec>(r.codec), r.offset,
                         r.stored_length, r.decoded_length, r.crc32c);
}

flatbuffers::Offset<flatbuffers::Vector<flatbuffers::Offset<flatbuffers::String>>> build_strings(
    flatbuffers::FlatBufferBuilder& b, const std::vector<std::string>& v) {
  return b.CreateVectorOfStrings(v);
}

const char* dtype_name(std::uint8_t v) { return v == kDTypeF64 ? "f64" : "f32"; }
const char* order_name(std::uint8_t v) { return v == kOrderColumnMajor ? "column_major" : "component_major"; }
const char* filter_name(std::uint8_t v) {
  return v == kFilterQuantized ? "quantized" : v == kFilterByteStreamSplit ? "byte_stream_split" : "none";
}
const char* codec_name(std::uint8_t v) { return v == kCodecZstd ? "zstd" : "none"; }

ArrayInfo to_info(const ArrayRecord& r) {
  ArrayInfo a;
  a.dtype = dtype_name(r.dtype);
  a.order = order_name(r.order);
  a.filter = filter_name(r.filter);
  a.codec = codec_name(r.codec);
  a.offset = r.offset;
  a.stored_length = r.stored_length;
  a.decoded_length = r.decoded_length;
  a.crc32c = r.crc32c;
  return a;
}

ArrayRecord to_record(const fb::Array* a) {
  ArrayRecord r;
  r.dtype = static_cast<std::uint8_t>(a->dtype());
  r.order = static_cast<std::uint8_t>(a->order());
  r.filter = static_cast<std::uint8_t>(a->filter());
  r.codec = static_cast<std::uint8_t>(a->codec());
  r.offset = a->offset();
  r.stored_length = a->stored_length();
  r.decoded_length = a->decoded_length();
  r.crc32c = a->crc32c();
  return r;
}

std::string str(const flatbuffers::String* s) { return s ? s->str() : std::string(); }

bool strings_equal(const flatbuffers::Vector<flatbuffers::Offset<flatbuffers::String>>* v,
                   const std::vector<std::string>& expected) {
  if (v->size() != expected.size()) return false;
  for (flatbuffers::uoffset_t i = 0; i < v->size(); ++i) {
    if (v->Get(i)->str() != expected[i]) return false;
  }
  return true;
}

const char* const kArrayNames[3] = {"weights", "means", "covariances"};

// Step 11, strings (spec/format.md section 4.4): every string the reader
// decodes is valid UTF-8 without NUL, and together they are no longer than the
// block. FlatBuffers lets many fields point at one string, so without the
// total a small block could decode to gigabytes; every reference counts.
void check_metadata_strings(const fb::SogmmFile* root, std::uint64_t block_length) {
  std::uint64_t total = 0;
  auto check = [&](const flatbuffers::String* s, const auto& what) {
    if (s == nullptr) return;
    total += s->size();  // at most 100 000 tables x 2 strings of < 2^31 bytes: no overflow
    const std::string problem = metadata_string_problem(s->c_str(), s->size());
    if (!problem.empty()) fail(F, "bad_metadata", what() + ": " + problem);
  };
  check(root->producer_name(), [] { return std::string("producer name"); });
  check(root->producer_version(), [] { return std::string("producer version"); });
  if (const auto* kvs = root->key_values()) {
    for (flatbuffers::uoffset_t i = 0; i < kvs->size(); ++i) {
      check(kvs->Get(i)->key(), [i] { return "key of key/value pair " + std::to_string(i); });
      check(kvs->Get(i)->value(), [i] { return "value of key/value pair " + std::to_string(i); });
    }
  }
  if (total > block_length) {
    fail(F, "bad_metadata",
         "metadata strings total " + std::to_string(total) + " bytes (shared strings counted once per use), " +
             "more than the " + std::to_string(block_length) + " bytes of the metadata block");
  }
}

}  // namespace

flatbuffers::DetachedBuffer build_metadata(const Model& model, const ArrayRecord (&arrays)[3], std::uint64_t n_declared,
                                           bool packed, const Tweaks& t, std::size_t size_hint) {
  flatbuffers::FlatBufferBuilder b(size_hint);
  // Children first (FlatBuffers builds bottom-up).
  const auto weights = build_array(b, arrays[kWeights]);
  const auto means = build_array(b, arrays[kMeans]);
  const auto covariances = build_array(b, arrays[kCovariances]);
  const bool axis_lists = t.axis_lists.value_or(true);
  flatbuffers::Offset<flatbuffers::Vector<flatbuffers::Offset<flatbuffers::String>>> labels, units;
  if (axis_lists) {
    labels = build_strings(b, kAxisLabels);
    units = build_strings(b, t.axis_units ? *t.axis_units : kAxisUnits);
  }
  flatbuffers::Offset<fb::FitInfo> fit;
  if (model.fit.known) {
    const FitInfo& f = model.fit;
    fit = fb::CreateFitInfo(b, f.bandwidth, f.n_components_requested, f.tol, f.reg_covar, f.max_iter, f.n_iter,
                            f.converged, f.log_likelihood, f.seed);
  }
  flatbuffers::Offset<fb::Camera> camera;
  if (model.camera.known) {
    const CameraInfo& c = model.camera;
    camera = fb::CreateCamera(b, c.camera.width, c.camera.height, c.camera.fx, c.camera.fy, c.camera.cx, c.camera.cy,
                              c.decimation, c.depth_scale, c.depth_min, c.depth_max);
  }
  flatbuffers::Offset<flatbuffers::Vector<double>> pose;
  if (t.raw_pose) {
    pose = b.CreateVector(*t.raw_pose);
  } else if (model.pose) {
    pose = b.CreateVector(model.pose->data(), model.pose->size());
  }
  const auto producer_name = b.CreateString(model.producer_name);
  const std::string version = model.producer_version.empty() ? std::string(sogmm::version_string())
                                                              : model.producer_version;
  const auto producer_version = b.CreateString(version);
  flatbuffers::Offset<flatbuffers::Vector<flatbuffers::Offset<fb::KeyValue>>> kvs;
  if (!model.key_values.empty()) {
    std::vector<flatbuffers::Offset<fb::KeyValue>> items;
    for (const auto& kv : model.key_values) {
      const auto k = t.share_strings ? b.CreateSharedString(kv.first) : b.CreateString(kv.first);
      const auto v = t.share_strings ? b.CreateSharedString(kv.second) : b.CreateString(kv.second);
      items.push_back(fb::CreateKeyValue(b, k, v));
    }
    kvs = b.CreateVector(items);
  }
  flatbuffers::Offset<flatbuffers::String> unknown_string;
  if (t.unknown_optional_fields) unknown_string = b.CreateString("a field from format 1.1");

  fb::SogmmFileBuilder root(b);
  root.add_n_components(n_declared);
  if (t.dims) root.fbb_.AddElement<std::uint32_t>(fb::SogmmFile::VT_DIMS, *t.dims);  // written even when 4
  root.add_support_size(model.gmm.support_size);
  root.add_covariance_layout(packed ? fb::CovarianceLayout::UPPER_PACKED : fb::CovarianceLayout::FULL);
  root.add_weights(weights);
  root.add_means(means);
  root.add_covariances(covariances);
  root.add_features_required(t.features_required);
  root.add_features_used(t.features_used);
  if (axis_lists) {
    root.add_axis_labels(labels);
    root.add_axis_units(units);
  }
  if (!fit.IsNull()) root.add_fit(fit);
  if (!camera.IsNull()) root.add_camera(camera);
  if (!pose.IsNull()) root.add_pose(pose);
  root.add_producer_name(producer_name);
  root.add_producer_version(producer_version);
  root.add_created_unix_ms(model.created_unix_ms);
  if (!kvs.IsNull()) root.add_key_values(kvs);
  if (t.unknown_optional_fields) {
    // Fields 20 (ulong) and 21 (string): unknown to a 1.0 reader, which must ignore them.
    root.fbb_.AddElement<std::uint64_t>(flatbuffers::FieldIndexToOffset(20), 0x1122334455667788ull, 0);
    root.fbb_.AddOffset(flatbuffers::FieldIndexToOffset(21), unknown_string);
  }
  b.Finish(root.Finish(), fb::SogmmFileIdentifier());
  return b.Release();
}

void set_array_offsets(std::uint8_t* metadata, const std::uint64_t (&offsets)[3], const bool (&patch)[3]) {
  fb::SogmmFile* root = fb::GetMutableSogmmFile(metadata);
  fb::Array* const arrays[3] = {root->mutable_weights(), root->mutable_means(), root->mutable_covariances()};
  for (int i = 0; i < 3; ++i) {
    if (patch[i] && !arrays[i]->mutate_offset(offsets[i])) {
      throw std::logic_error(std::string(kArrayNames[i]) + ": the metadata has no offset field to patch");
    }
  }
}

ParsedMetadata parse_metadata(const std::uint8_t* buf, const Header& h, const ReadOptions& options,
                              std::uint64_t known_features) {
  // 9. The wire rules of section 4.3 decide. FlatBuffers' own verifier, whose
  // rules are weaker, then only guards the generated accessors used below.
  verify_wire(buf, h.metadata_length);
  flatbuffers::Verifier verifier(buf, h.metadata_length, /*max_depth=*/64, kMaxMetadataTables);
  if (!fb::VerifySogmmFileBuffer(verifier)) fail(F, "bad_metadata", "metadata fails FlatBuffers verification");
  const fb::SogmmFile* root = fb::GetSogmmFile(buf);

  // 10. required features
  const std::uint64_t unknown = root->features_required() & ~known_features;
  if (unknown != 0) {
    fail(F, "unsupported_feature", "file requires feature bits 0x" + [&] {
      char hex[32];
      std::snprintf(hex, sizeof hex, "%llx", static_cast<unsigned long long>(unknown));
      return std::string(hex);
    }() + " that this reader does not know");
  }

  // 11. metadata values
  if (root->dims() != 4) fail(F, "bad_metadata", "dims is " + std::to_string(root->dims()) + ", not 4");
  if (root->axis_labels() && !strings_equal(root->axis_labels(), kAxisLabels)) {
    fail(F, "bad_metadata", "axis labels are not (x, y, z, gray)");
  }
  if (root->axis_units() && !strings_equal(root->axis_units(), kAxisUnits)) {
    fail(F, "bad_metadata", "axis units are not (m, m, m, 1)");
  }
  if (root->gray_min() != 0.0 || root->gray_max() != 1.0) fail(F, "bad_metadata", "gray range is not [0, 1]");
  check_metadata_strings(root, h.metadata_length);
  ParsedMetadata out;
  Model& model = out.info.metadata;
  if (const fb::FitInfo* f = root->fit()) {
    model.fit.known = true;
    model.fit.bandwidth = f->bandwidth();
    model.fit.n_components_requested = f->n_components_requested();
    model.fit.tol = f->tol();
    model.fit.reg_covar = f->reg_covar();
    model.fit.max_iter = f->max_iter();
    model.fit.n_iter = f->n_iter();
    // A bool is the byte 0 or 1 (section 4.3); FlatBuffers would read any other byte as true.
    const auto converged = reinterpret_cast<const flatbuffers::Table*>(f)->GetField<std::uint8_t>(
        fb::FitInfo::VT_CONVERGED, 0);
    if (converged > 1) fail(F, "bad_metadata", "fit.converged is " + std::to_string(converged) + ", not 0 or 1");
    model.fit.converged = converged == 1;
    model.fit.log_likelihood = f->log_likelihood();
    model.fit.seed = f->seed();
  }
  if (const fb::Camera* c = root->camera()) {
    model.camera.known = true;
    model.camera.camera.width = c->width();
    model.camera.camera.height = c->height();
    model.camera.camera.fx = c->fx();
    model.camera.camera.fy = c->fy();
    model.camera.camera.cx = c->cx();
    model.camera.camera.cy = c->cy();
    model.camera.decimation = c->decimation();
    model.camera.depth_scale = c->depth_scale();
    model.camera.depth_min = c->depth_min();
    model.camera.depth_max = c->depth_max();
  }
  check_metadata_numbers(model, F);
  if (root->pose()) {
    if (root->pose()->size() != 16) {
      fail(F, "bad_metadata", "pose has " + std::to_string(root->pose()->size()) + " values, not 16");
    }
    std::array<double, 16> pose{};
    for (int i = 0; i < 16; ++i) pose[i] = root->pose()->Get(i);
    check_pose(pose);
    model.pose = pose;
  }

  // 12. encodings
  const auto layout = static_cast<std::uint8_t>(root->covariance_layout());
  if (layout > 1) fail(F, "unsupported_encoding", "unknown covariance layout " + std::to_string(layout));
  out.packed = layout == 0;
  out.quantized = (root->features_required() & kFeatureQuantizedComponents) != 0;
  const fb::Array* arrays[3] = {root->weights(), root->means(), root->covariances()};
  for (int i = 0; i < 3; ++i) {
    out.arrays[i] = to_record(arrays[i]);
    const ArrayRecord& r = out.arrays[i];
    const std::string name = kArrayNames[i];
    if (r.dtype > 1) fail(F, "unsupported_encoding", name + ": unknown dtype " + std::to_string(r.dtype));
    if (r.order > 1) fail(F, "unsupported_encoding", name + ": unknown element order " + std::to_string(r.order));
    if (r.filter > 2) fail(F, "unsupported_encoding", name + ": unknown filter " + std::to_string(r.filter));
    if (r.codec > 1) fail(F, "unsupported_encoding", name + ": unknown codec " + std::to_string(r.codec));
    // Quantized codes (section 5.7) come with their feature bit, in all
    // three arrays, as float32 packed covariances, and never without it.
    if ((r.filter == kFilterQuantized) != out.quantized) {
      fail(F, "unsupported_encoding",
           name + (out.quantized ? ": filter is not QUANTIZED in a file with feature bit 2"
                                 : ": filter QUANTIZED without feature bit 2"));
    }
    if (out.quantized && (r.dtype != kDTypeF32 || !out.packed)) {
      fail(F, "unsupported_encoding", name + ": quantized components decode to float32, packed covariances only");
    }
  }

  // 13. M
  const std::uint64_t m = root->n_components();
  // A map delta may carry no component (a frame that only added provenance).
  if (m == 0 && (root->features_required() & kFeatureMapDelta) == 0)
    fail(ErrorCode::InvalidData, "empty", "model has no components (M = 0)");

  // 14. declared lengths agree with M
  std::uint64_t total = 0;
  bool total_overflow = false;
  for (int i = 0; i < 3; ++i) {
    const ArrayRecord& r = out.arrays[i];
    std::uint64_t expected = 0, mc = 0;
    const bool overflow = !checked::try_mul<std::uint64_t>(m, columns(i, out.packed), &mc) ||
                          !checked::try_mul<std::uint64_t>(mc, r.dtype == kDTypeF64 ? 8 : 4, &expected);
    if (overflow || r.decoded_length != expected) {
      fail(ErrorCode::InvalidData, "length_mismatch",
           std::string(kArrayNames[i]) + " declare " + std::to_string(r.decoded_length) +
               " decoded bytes, which disagrees with M = " + std::to_string(m));
    }
    if (!checked::try_add(total, expected, &total)) total_overflow = true;
  }

  // 15. size cap
  if (total_overflow || total > options.max_decoded_bytes) {
    fail(ErrorCode::Limit, "limit",
         "arrays declare " + std::to_string(total) + " decoded bytes, over the cap of " +
             std::to_string(options.max_decoded_bytes));
  }

  // 16. buffer layout
  const std::uint64_t body = body_start(h);
  const std::uint64_t body_end = h.file_length - kTrailerSize;
  for (int i = 0; i < 3; ++i) {
    const ArrayRecord& r = out.arrays[i];
    const std::string name = kArrayNames[i];
    if (r.offset % 8 != 0) fail(F, "bad_layout", name + ": offset is not a multiple of 8");
    if (r.offset < body || r.offset > body_end || r.stored_length > body_end - r.offset) {
      fail(F, "bad_layout", name + ": stored bytes lie outside the body");
    }
    if (r.codec == kCodecNone && r.stored_length != filtered_length(out, i)) {
      fail(F, "bad_layout", name + ": uncompressed but stored length differs from decoded length");
    }
    for (int j = 0; j < i; ++j) {
      const ArrayRecord& o = out.arrays[j];
      // Half-open byte ranges: an empty array overlaps nothing.
      if (r.stored_length > 0 && o.stored_length > 0 && r.offset < o.offset + o.stored_length &&
          o.offset < r.offset + r.stored_length) {
        fail(F, "bad_layout", name + " overlap " + kArrayNames[j]);
      }
    }
  }

  // File info and the metadata as a Model.
  FileInfo& info = out.info;
  info.format_major = h.major;
  info.format_minor = h.minor;
  info.file_length = h.file_length;
  info.metadata_length = h.metadata_length;
  info.features_required = root->features_required();
  info.features_used = root->features_used();
  info.covariance_layout = out.packed ? "upper_packed" : "full";
  info.n_components = m;
  info.weights = to_info(out.arrays[kWeights]);
  info.means = to_info(out.arrays[kMeans]);
  info.covariances = to_info(out.arrays[kCovariances]);
  model.gmm.support_size = root->support_size();
  model.producer_name = str(root->producer_name());
  model.producer_version = str(root->producer_version());
  model.created_unix_ms = root->created_unix_ms();
  if (root->key_values()) {
    model.key_values.reserve(root->key_values()->size());
    for (const fb::KeyValue* kv : *root->key_values()) model.key_values.emplace_back(str(kv->key()), str(kv->value()));
  }
  return out;
}

}  // namespace sogmm::format::detail
