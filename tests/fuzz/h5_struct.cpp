/// libFuzzer harness, structure-aware: pdcg's own validation of model (body) and result /
/// checkpoint files that are *valid HDF5*.
///
/// Mutated HDF5 bytes mostly exercise (and crash) HDF5 1.10.8's own parser (model_file and
/// h5_result replay their corpus only). Here the input is a list of edits instead: the first
/// byte picks a template (a pdcg body with lj/cut, one with eam, a result file, a checkpoint,
/// loaded once from tests/fuzz/corpus/), and the following bytes edit its content — delete a
/// dataset or attribute, set an element to an extreme or non-finite value, resize or reshape a
/// dataset, change its type (double / int64 / string), copy one dataset over another, edit a
/// string (the stored LAMMPS command lines, embedded potential files, names), change the
/// format / schema / units identification, drop or falsify a dataset's crc32. The harness
/// then writes a valid HDF5 file with pdcg's H5Writer (which stores correct checksums, so the
/// values reach the readers' own checks) plus the HDF5 C API for the deletions and checksum
/// edits, and reads it: read_body (with the default potential factory, native styles only)
/// for bodies, H5Reader's walk (h5_walk.hpp) and verify() for results and checkpoints.
///
/// The file lives in memory (io::InMemory: HDF5's core driver and file images), and HDF5's
/// free lists keep what they free: every variable-length string read or written takes a
/// 1 MiB type-conversion buffer, which HDF5's default limits return to malloc at once, and
/// under ASan each one was a fresh mmap, zeroed page by page and unmapped — half the time of
/// an execution (docs/reliability.md, "Fuzzing").
///
/// Not covered: HDF5 structures H5Writer never writes (other datatypes such as float32 or
/// fixed-length strings, chunked or compressed layouts, attributes that are arrays, links) —
/// those only reach H5Reader's type checks through the model_file / h5_result corpus.
#include <fuzzer/FuzzedDataProvider.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_common.hpp"
#include "fuzz_potential.hpp"
#include "h5_walk.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/body/model_file.hpp"

namespace {

using pdcg::io::FileInfo;

struct Value {
  enum Kind { dbl, i64, str, strs } kind = dbl;
  std::vector<double> d;
  std::vector<std::int64_t> i;
  std::vector<std::string> s;
  std::vector<std::size_t> dims;  // datasets only; empty = {size}
  std::size_t size() const { return kind == dbl ? d.size() : kind == i64 ? i.size() : s.size(); }
};
struct Item {
  std::string object, name;  // dataset: object = its path, name empty; attribute: both
  Value v;
};
struct Template {
  FileInfo info;
  bool body = false;
  std::vector<Item> sets, attrs;
};

/// Loads a pdcg HDF5 file into a Template: every dataset, every attribute but the crc32 ones
/// (H5Writer recomputes those).
Template load(const std::string& path) {
  Template t;
  pdcg::io::H5Reader r(path);
  t.info = r.info();
  t.body = t.info.format == "pdcg-body";
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) std::abort();
  std::vector<std::pair<std::string, H5O_type_t>> objects;
  H5Ovisit2(
      f, H5_INDEX_NAME, H5_ITER_INC,
      [](hid_t, const char* name, const H5O_info_t* info, void* data) -> herr_t {
        const std::string n(name);
        static_cast<std::vector<std::pair<std::string, H5O_type_t>>*>(data)->emplace_back(
            n == "." ? "/" : "/" + n, info->type);
        return 0;
      },
      &objects, H5O_INFO_BASIC);
  for (const auto& [p, type] : objects) {
    hid_t o = H5Oopen(f, p.c_str(), H5P_DEFAULT);
    std::vector<std::string> names;
    H5Aiterate2(
        o, H5_INDEX_NAME, H5_ITER_INC, nullptr,
        [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
          static_cast<std::vector<std::string>*>(data)->emplace_back(name);
          return 0;
        },
        &names);
    for (const auto& n : names) {
      if (n == "crc32") continue;
      hid_t a = H5Aopen(o, n.c_str(), H5P_DEFAULT);
      hid_t at = H5Aget_type(a);
      const H5T_class_t c = H5Tget_class(at);
      H5Tclose(at);
      H5Aclose(a);
      Item it{p, n, {}};
      if (c == H5T_FLOAT) {
        it.v.kind = Value::dbl;
        it.v.d = {r.attribute_double(p, n)};
      } else if (c == H5T_INTEGER) {
        it.v.kind = Value::i64;
        it.v.i = {r.attribute_int(p, n)};
      } else {
        it.v.kind = Value::str;
        it.v.s = {r.attribute_string(p, n)};
      }
      t.attrs.push_back(std::move(it));
    }
    if (type == H5O_TYPE_DATASET) {
      hid_t dt = H5Dget_type(o);
      const H5T_class_t c = H5Tget_class(dt);
      H5Tclose(dt);
      Item it{p, "", {}};
      it.v.dims = r.dims(p);
      if (c == H5T_FLOAT) {
        it.v.d = r.read_double(p);
      } else if (c == H5T_INTEGER) {
        it.v.kind = Value::i64;
        it.v.i = r.read_int(p);
      } else if (it.v.dims.empty()) {
        it.v.kind = Value::str;
        it.v.s = {r.read_string(p)};
      } else {
        it.v.kind = Value::strs;
        it.v.s = r.read_strings(p);
      }
      t.sets.push_back(std::move(it));
    }
    H5Oclose(o);
  }
  H5Fclose(f);
  return t;
}

const std::vector<Template>& templates() {
  static const std::vector<Template> all = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    // HDF5's free lists keep what they free (see the file comment), up to 4 MiB per list and
    // 16 MiB (regular objects, arrays) or 64 MiB (blocks) in all: the 1 MiB conversion
    // buffers are reused, and memory stays bounded over 10^6 inputs of varying sizes.
    constexpr int MiB = 1 << 20;
    if (H5set_free_list_limits(16 * MiB, 4 * MiB, 16 * MiB, 4 * MiB, 64 * MiB, 4 * MiB) < 0)
      std::abort();
    std::vector<Template> v;
    const std::string dir = PDCG_FUZZ_CORPUS_DIR;
    for (const char* f : {"/model_file/lj_body.h5", "/model_file/cu_body.h5",
                          "/h5_result/results.h5", "/h5_result/checkpoint.h5"})
      v.push_back(load(dir + f));
    return v;
  }();
  return all;
}

double fuzz_double(FuzzedDataProvider& in, double old) {
  switch (in.ConsumeIntegralInRange<int>(0, 13)) {
    case 0:
      return std::numeric_limits<double>::quiet_NaN();
    case 1:
      return std::numeric_limits<double>::infinity();
    case 2:
      return -std::numeric_limits<double>::infinity();
    case 3:
      return 0.0;
    case 4:
      return -0.0;
    case 5:
      return 1e308;
    case 6:
      return -1e308;
    case 7:
      return std::numeric_limits<double>::denorm_min();
    case 8:
      return -1.0;
    case 9:
      return -old;
    case 10:
      return old * (1.0 + 1e-12);
    case 11:
      return old * in.ConsumeIntegralInRange<int>(-4, 1000);
    case 12:
      return 9007199254740993.0;  // 2^53 + 1 (rounded): beyond exact integers
    default:
      return in.ConsumeFloatingPoint<double>();
  }
}

std::int64_t fuzz_int(FuzzedDataProvider& in, std::int64_t old) {
  switch (in.ConsumeIntegralInRange<int>(0, 11)) {
    case 0:
      return std::numeric_limits<std::int64_t>::min();
    case 1:
      return std::numeric_limits<std::int64_t>::max();
    case 2:
      return -1;
    case 3:
      return 0;
    case 4:
      return std::int64_t{std::numeric_limits<std::int32_t>::max()} + 1;
    case 5:
      return std::int64_t{std::numeric_limits<std::int32_t>::min()} - 1;
    case 6:  // wrapping (two's complement): old may be the extreme values above
      return static_cast<std::int64_t>(static_cast<std::uint64_t>(old) + 1);
    case 7:
      return static_cast<std::int64_t>(static_cast<std::uint64_t>(old) - 1);
    case 8:
      return static_cast<std::int64_t>(0 - static_cast<std::uint64_t>(old));
    case 9:
      return 128;
    case 10:
      return in.ConsumeIntegralInRange<std::int64_t>(-8, 64);
    default:
      return in.ConsumeIntegral<std::int64_t>();
  }
}

std::string fuzz_string(FuzzedDataProvider& in, const std::string& old) {
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0:
      return in.ConsumeRandomLengthString(256);
    case 1:
      return old + in.ConsumeRandomLengthString(64);
    case 2:
      return old.substr(0, in.ConsumeIntegralInRange<std::size_t>(0, old.size()));
    case 3: {  // replace a span
      std::string s = old;
      const std::size_t at = in.ConsumeIntegralInRange<std::size_t>(0, s.size());
      const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, s.size() - at);
      s.replace(at, n, in.ConsumeRandomLengthString(32));
      return s;
    }
    default:
      return "";
  }
}

template <class V>
std::size_t pick(FuzzedDataProvider& in, const V& v) {
  return in.ConsumeIntegralInRange<std::size_t>(0, v.size() - 1);
}

void set_element(FuzzedDataProvider& in, Value& v) {
  if (v.size() == 0) return;
  const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(0, v.size() - 1);
  if (v.kind == Value::dbl) v.d[k] = fuzz_double(in, v.d[k]);
  if (v.kind == Value::i64) v.i[k] = fuzz_int(in, v.i[k]);
  if (v.kind == Value::str || v.kind == Value::strs) v.s[k] = fuzz_string(in, v.s[k]);
}

void resize(FuzzedDataProvider& in, Value& v) {
  const std::size_t old = v.size();
  const std::size_t n =
      in.ConsumeIntegralInRange<std::size_t>(0, std::min<std::size_t>(2 * old + 8, 1 << 14));
  const bool fuzz_fill = in.ConsumeBool();
  if (v.kind == Value::dbl) {
    const double fill = fuzz_fill ? fuzz_double(in, 1.0) : (old ? v.d.back() : 0.0);
    v.d.resize(n, fill);
  } else if (v.kind == Value::i64) {
    const std::int64_t fill = fuzz_int(in, old ? v.i.back() : 0);
    v.i.resize(n, fill);
  } else {
    v.s.resize(std::max<std::size_t>(n, v.kind == Value::str ? 1 : 0));
    if (v.kind == Value::str) v.s.resize(1);
  }
  v.dims.clear();  // {size}
}

void reshape(FuzzedDataProvider& in, Value& v) {
  if (v.kind == Value::str) return;
  const std::size_t n = v.size();
  const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(1, 9);
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      v.dims = {n};
      break;
    case 1:
      if (n % k == 0) v.dims = {n / k, k};
      break;
    case 2:
      if (n % k == 0) v.dims = {k, n / k};
      break;
    default:
      if (n % k == 0) v.dims = {n / k, 1, k};
      break;
  }
}

void change_kind(FuzzedDataProvider& in, Value& v) {
  const auto to = static_cast<Value::Kind>(in.ConsumeIntegralInRange<int>(0, 3));
  if (to == v.kind) return;
  Value w;
  w.kind = to;
  const std::size_t n = v.size();
  for (std::size_t k = 0; k < n; ++k) {
    double x = v.kind == Value::dbl ? v.d[k] : v.kind == Value::i64 ? double(v.i[k]) : 0.0;
    if (v.kind == Value::str || v.kind == Value::strs) x = std::atof(v.s[k].c_str());
    if (to == Value::dbl) w.d.push_back(x);
    if (to == Value::i64)
      w.i.push_back(std::isfinite(x) && std::abs(x) < 9e18 ? static_cast<std::int64_t>(x) : 0);
    if (to == Value::strs || to == Value::str) {
      w.s.push_back(v.kind == Value::str || v.kind == Value::strs ? v.s[k] : std::to_string(x));
      if (to == Value::str) break;
    }
  }
  if (to == Value::str && w.s.empty()) w.s = {""};
  if (to != Value::str && v.dims.size() > 1 && w.size() == n) w.dims = v.dims;
  v = std::move(w);
}

struct PostEdit {
  std::string object, name;
  bool remove = true;
  std::int64_t crc = 0;
};

/// Where the readers' messages say the file is.
const char* const kName = "fuzz_h5_struct input (in memory)";

/// The edited template as an HDF5 file image.
pdcg::io::H5Image write_file(const Template& t, const std::vector<PostEdit>& post) {
  pdcg::io::H5Image image;
  {
    pdcg::io::H5Writer w(pdcg::io::InMemory{kName}, t.info);
    for (const auto& s : t.sets) {
      const Value& v = s.v;
      if (v.kind == Value::dbl) w.write(s.object, std::span<const double>(v.d), v.dims);
      if (v.kind == Value::i64) w.write(s.object, std::span<const std::int64_t>(v.i), v.dims);
      if (v.kind == Value::str) w.write(s.object, v.s.empty() ? std::string() : v.s[0]);
      if (v.kind == Value::strs) w.write_strings(s.object, v.s);
    }
    for (const auto& a : t.attrs) {
      const Value& v = a.v;
      if (v.kind == Value::dbl) w.attribute(a.object, a.name, v.d.at(0));
      if (v.kind == Value::i64) w.attribute(a.object, a.name, v.i.at(0));
      if (v.kind == Value::str || v.kind == Value::strs)
        w.attribute(a.object, a.name, std::string_view(v.s.empty() ? "" : v.s[0]));
    }
    w.commit();
    image = w.image();
  }
  if (post.empty()) return image;
  // the image opened for writing in memory (core driver, no backing store), edited, taken back
  hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  if (fapl < 0 || H5Pset_fapl_core(fapl, 64 * 1024, 0) < 0 ||
      H5Pset_file_image(fapl, image.data(), image.size()) < 0)
    std::abort();
  hid_t f = H5Fopen("fuzz_h5_struct post-edit", H5F_ACC_RDWR, fapl);
  H5Pclose(fapl);
  if (f < 0) std::abort();
  for (const auto& e : post) {
    if (H5Aexists_by_name(f, e.object.c_str(), e.name.c_str(), H5P_DEFAULT) <= 0) continue;
    if (e.remove) {
      H5Adelete_by_name(f, e.object.c_str(), e.name.c_str(), H5P_DEFAULT);
    } else {
      // through the open object: HDF5 1.10.8 refuses H5Awrite on an attribute opened with
      // H5Aopen_by_name ("can't locate open attribute"), and the wrong checksum never landed
      hid_t o = H5Oopen(f, e.object.c_str(), H5P_DEFAULT);
      hid_t a = H5Aopen(o, e.name.c_str(), H5P_DEFAULT);
      if (o < 0 || a < 0 || H5Awrite(a, H5T_NATIVE_INT64, &e.crc) < 0) std::abort();
      H5Aclose(a);
      H5Oclose(o);
    }
  }
  if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) std::abort();
  const ssize_t n = H5Fget_file_image(f, nullptr, 0);
  image.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  if (n <= 0 || H5Fget_file_image(f, image.data(), image.size()) != n) std::abort();
  if (H5Fclose(f) < 0) std::abort();
  return image;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& all = templates();
  FuzzedDataProvider in(data, size);
  Template t = all[in.ConsumeIntegral<std::uint8_t>() % all.size()];
  std::vector<PostEdit> post;
  for (int op = 0; op < 32 && in.remaining_bytes() > 0; ++op) {
    const int what = in.ConsumeIntegralInRange<int>(0, 11);
    const bool sets = !t.sets.empty(), attrs = !t.attrs.empty();
    if (what == 0 && sets) t.sets.erase(t.sets.begin() + pick(in, t.sets));
    if (what == 1 && attrs) t.attrs.erase(t.attrs.begin() + pick(in, t.attrs));
    if (what == 2 && sets) set_element(in, t.sets[pick(in, t.sets)].v);
    if (what == 3 && sets) resize(in, t.sets[pick(in, t.sets)].v);
    if (what == 4 && sets) reshape(in, t.sets[pick(in, t.sets)].v);
    if (what == 5 && sets) change_kind(in, t.sets[pick(in, t.sets)].v);
    if (what == 6 && attrs) set_element(in, t.attrs[pick(in, t.attrs)].v);
    if (what == 7 && attrs) {
      Value& v = t.attrs[pick(in, t.attrs)].v;
      change_kind(in, v);
      if (v.size() == 0) v = Value{Value::i64, {}, {0}, {}, {}};
    }
    if (what == 8 && sets) {  // one dataset's content in another's place
      const Value v = t.sets[pick(in, t.sets)].v;
      t.sets[pick(in, t.sets)].v = v;
    }
    if (what == 9) {
      const int k = in.ConsumeIntegralInRange<int>(0, 3);
      if (k == 0)
        t.info.format = in.PickValueInArray<std::string>(
            {"pdcg-body", "pdcg-results", "pdcg-checkpoint", "pdcg-", ""});
      if (k == 1) t.info.schema_version = static_cast<int>(fuzz_int(in, t.info.schema_version));
      if (k == 2)
        t.info.units =
            in.PickValueInArray({pdcg::UnitStyle::lj, pdcg::UnitStyle::metal, pdcg::UnitStyle::real,
                                 pdcg::UnitStyle::si, pdcg::UnitStyle::none});
      if (k == 3) t.info.pdcg_version = in.ConsumeRandomLengthString(16);
    }
    if (what == 10 && attrs) {  // a root identification attribute or another one dropped
      const auto& a = t.attrs[pick(in, t.attrs)];
      post.push_back({a.object, a.name});
    }
    if (what == 11 && sets) {  // a dataset's checksum dropped or wrong
      PostEdit e{t.sets[pick(in, t.sets)].object, "crc32"};
      e.remove = in.ConsumeBool();
      e.crc = fuzz_int(in, 0);
      post.push_back(e);
    }
  }
  pdcg::io::H5Image image;
  try {
    image = write_file(t, post);
  } catch (const pdcg::Error&) {
    return 0;  // the writer refused the structure (e.g. a dataset where a group is): no file
  }
  const bool body = t.body;
  return pdcg::fuzz::guarded([&] {
    const pdcg::io::H5Reader file(pdcg::io::InMemory{kName}, image);
    if (body) {
      const pdcg::body::PotentialFactory native_only =
          [](const pdcg::atomistic::PotentialSpec& spec,
             const std::vector<pdcg::body::EmbeddedFile>& files)
          -> std::shared_ptr<const pdcg::atomistic::Potential> {
        if (!pdcg::fuzz::native_style(spec.pair_style))
          throw pdcg::InputError("non-native pair style (not fuzzed)").value(spec.pair_style);
        // potential_from_commands builds from the stored command lines, which an edit may
        // have made name another style than the stored pair_style: check what it will build
        // (a non-native style would start embedded LAMMPS, and Open MPI's start-up leaks
        // would end the run at exit)
        std::string text;
        for (const auto& l : spec.lines) text += l + "\n";
        const auto rebuilt =
            pdcg::atomistic::read_potential_commands_from_string(text, "fuzz", spec.ntypes);
        if (!pdcg::fuzz::native_style(rebuilt.pair_style))
          throw pdcg::InputError("non-native pair style (not fuzzed)").value(rebuilt.pair_style);
        return pdcg::body::potential_from_commands(spec, files);
      };
      (void)pdcg::body::read_body(file, native_only);
    } else {
      pdcg::fuzz::walk_h5(file);
      file.verify();
    }
  });
}
