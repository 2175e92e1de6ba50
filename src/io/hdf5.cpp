#include "pdcg/io/hdf5.hpp"

#include <hdf5.h>

#include <fmt/format.h>

#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"
#include "pdcg/core/version.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace pdcg::io {

namespace {

/// RAII for an hid_t with its close function.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = -1;
    }
    return *this;
  }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = -1;
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

/// Silences HDF5's own error stack printing; we report errors ourselves.
struct QuietHdf5 {
  QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }
};
const QuietHdf5 g_quiet;

[[noreturn]] void fail(std::string_view what, const std::filesystem::path& file,
                       std::string_view path) {
  throw Error(fmt::format("HDF5: {} '{}' in {}", what, path, file.string()));
}

Handle string_type() {
  Handle t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

Handle open_object(hid_t file, std::string_view path) {
  const std::string p(path.empty() ? "/" : path);
  hid_t id = H5Oopen(file, p.c_str(), H5P_DEFAULT);
  return Handle(id, H5Oclose);
}

}  // namespace

// ---------------------------------------------------------------- writer

struct H5Writer::Impl {
  AtomicPath path;
  Handle file;
  Handle link_props;
  explicit Impl(std::filesystem::path p) : path(std::move(p)) {}

  void write_array(std::string_view dpath, hid_t memtype, const void* data, std::size_t size,
                   std::vector<std::size_t> dims) {
    if (dims.empty()) dims = {size};
    std::size_t n = 1;
    for (auto d : dims) n *= d;
    if (n != size)
      throw Error(fmt::format("HDF5 write '{}': {} values do not fill dims of {} values", dpath,
                              size, n));
    std::vector<hsize_t> hd(dims.begin(), dims.end());
    Handle space(H5Screate_simple(static_cast<int>(hd.size()), hd.data(), nullptr), H5Sclose);
    const std::string p(dpath);
    Handle set(H5Dcreate2(file.get(), p.c_str(), memtype, space.get(), link_props.get(),
                          H5P_DEFAULT, H5P_DEFAULT),
               H5Dclose);
    if (!set.valid()) fail("cannot create dataset", path.temporary(), dpath);
    if (n > 0 && H5Dwrite(set.get(), memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
      fail("cannot write dataset", path.temporary(), dpath);
  }

  Handle object_for_attribute(std::string_view object) {
    Handle o = open_object(file.get(), object);
    if (!o.valid()) {
      // create the group if it does not exist yet
      const std::string p(object);
      Handle g(H5Gcreate2(file.get(), p.c_str(), link_props.get(), H5P_DEFAULT, H5P_DEFAULT),
               H5Gclose);
      if (!g.valid()) fail("cannot open or create object", path.temporary(), object);
      return g;
    }
    return o;
  }

  void put_attribute(std::string_view object, std::string_view name, hid_t type,
                     const void* value) {
    Handle o = object_for_attribute(object);
    const std::string n(name);
    if (H5Aexists(o.get(), n.c_str()) > 0) H5Adelete(o.get(), n.c_str());
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle a(H5Acreate2(o.get(), n.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose);
    if (!a.valid() || H5Awrite(a.get(), type, value) < 0)
      fail("cannot write attribute", path.temporary(), std::string(object) + "@" + n);
  }
};

H5Writer::H5Writer(std::filesystem::path final_path, FileInfo info)
    : impl_(std::make_unique<Impl>(std::move(final_path))) {
  impl_->file = Handle(H5Fcreate(impl_->path.temporary().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT,
                                 H5P_DEFAULT),
                       H5Fclose);
  if (!impl_->file.valid())
    throw InputError("cannot create HDF5 file")
        .value(impl_->path.final_path().string())
        .expected("a writable location")
        .fix("check that the directory exists and is writable");
  impl_->link_props = Handle(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(impl_->link_props.get(), 1);
  if (info.pdcg_version.empty()) info.pdcg_version = pdcg::version();
  if (info.command_line.empty()) info.command_line = pdcg::command_line();
  attribute("/", "format", info.format);
  attribute("/", "schema_version", static_cast<std::int64_t>(info.schema_version));
  attribute("/", "pdcg_version", info.pdcg_version);
  attribute("/", "units", to_string(info.units));
  attribute("/", "command_line", info.command_line);
}

H5Writer::~H5Writer() = default;  // Impl: file closes first, then AtomicPath removes the temp

void H5Writer::write(std::string_view path, std::span<const double> data,
                     std::vector<std::size_t> dims) {
  impl_->write_array(path, H5T_NATIVE_DOUBLE, data.data(), data.size(), std::move(dims));
}
void H5Writer::write(std::string_view path, std::span<const std::int64_t> data,
                     std::vector<std::size_t> dims) {
  impl_->write_array(path, H5T_NATIVE_INT64, data.data(), data.size(), std::move(dims));
}
void H5Writer::write(std::string_view path, std::string_view text) {
  Handle t = string_type();
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  const std::string p(path), s(text);
  const char* cs = s.c_str();
  Handle set(H5Dcreate2(impl_->file.get(), p.c_str(), t.get(), space.get(),
                        impl_->link_props.get(), H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!set.valid() || H5Dwrite(set.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &cs) < 0)
    fail("cannot write string", impl_->path.temporary(), path);
}
void H5Writer::write_strings(std::string_view path, const std::vector<std::string>& lines) {
  Handle t = string_type();
  hsize_t n = lines.size();
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  std::vector<const char*> ptrs;
  ptrs.reserve(lines.size());
  for (const auto& l : lines) ptrs.push_back(l.c_str());
  const std::string p(path);
  Handle set(H5Dcreate2(impl_->file.get(), p.c_str(), t.get(), space.get(),
                        impl_->link_props.get(), H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!set.valid() ||
      (n > 0 && H5Dwrite(set.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ptrs.data()) < 0))
    fail("cannot write strings", impl_->path.temporary(), path);
}

void H5Writer::attribute(std::string_view object, std::string_view name, double value) {
  impl_->put_attribute(object, name, H5T_NATIVE_DOUBLE, &value);
}
void H5Writer::attribute(std::string_view object, std::string_view name, std::int64_t value) {
  impl_->put_attribute(object, name, H5T_NATIVE_INT64, &value);
}
void H5Writer::attribute(std::string_view object, std::string_view name, std::string_view value) {
  Handle t = string_type();
  const std::string s(value);
  const char* cs = s.c_str();
  impl_->put_attribute(object, name, t.get(), &cs);
}

void H5Writer::commit() {
  if (H5Fflush(impl_->file.get(), H5F_SCOPE_GLOBAL) < 0)
    fail("cannot flush", impl_->path.temporary(), "/");
  impl_->file.reset();
  impl_->path.commit();
}

// ---------------------------------------------------------------- reader

struct H5Reader::Impl {
  std::filesystem::path path;
  Handle file;
  FileInfo info;

  Handle dataset(std::string_view p) const {
    const std::string s(p);
    if (H5Lexists(file.get(), s.c_str(), H5P_DEFAULT) <= 0)
      throw InputError("missing dataset")
          .source(path.string())
          .key(p)
          .expected("a pdcg file that holds it")
          .fix("check the file kind with `pdcg info`");
    Handle d(H5Dopen2(file.get(), s.c_str(), H5P_DEFAULT), H5Dclose);
    if (!d.valid()) fail("cannot open dataset", path, p);
    return d;
  }
  Handle attr(std::string_view object, std::string_view name) const {
    Handle o = open_object(file.get(), object);
    const std::string n(name);
    if (!o.valid() || H5Aexists(o.get(), n.c_str()) <= 0)
      throw InputError("missing attribute")
          .source(path.string())
          .key(std::string(object) + "@" + n)
          .expected("a pdcg file that holds it")
          .fix("check the file kind with `pdcg info`");
    return Handle(H5Aopen(o.get(), n.c_str(), H5P_DEFAULT), H5Aclose);
  }
};

H5Reader::H5Reader(std::filesystem::path path) : impl_(std::make_unique<Impl>()) {
  impl_->path = std::move(path);
  if (!std::filesystem::exists(impl_->path))
    throw InputError("file not found")
        .value(impl_->path.string())
        .expected("an existing pdcg HDF5 file")
        .fix("check the path");
  if (H5Fis_hdf5(impl_->path.c_str()) <= 0)
    throw InputError("not an HDF5 file")
        .value(impl_->path.string())
        .expected("a pdcg HDF5 file (.h5)")
        .fix("pass a file written by pdcg");
  impl_->file = Handle(H5Fopen(impl_->path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!impl_->file.valid()) fail("cannot open file", impl_->path, "/");
  if (!has_attribute("/", "format"))
    throw InputError("HDF5 file without a pdcg 'format' attribute")
        .value(impl_->path.string())
        .expected("a file written by pdcg")
        .fix("pass a file written by pdcg");
  impl_->info.format = attribute_string("/", "format");
  impl_->info.schema_version = static_cast<int>(attribute_int("/", "schema_version"));
  impl_->info.pdcg_version = attribute_string("/", "pdcg_version");
  impl_->info.units = parse_unit_style(attribute_string("/", "units"), impl_->path.string());
  impl_->info.command_line = attribute_string("/", "command_line");
}

H5Reader::~H5Reader() = default;

const FileInfo& H5Reader::info() const { return impl_->info; }
const std::filesystem::path& H5Reader::path() const { return impl_->path; }

void H5Reader::require_format(std::string_view format, int max_schema_version) const {
  if (impl_->info.format != format)
    throw InputError("wrong kind of pdcg file")
        .source(impl_->path.string())
        .key("format")
        .value(impl_->info.format)
        .expected(std::string(format))
        .fix("pass a file of that kind (`pdcg info FILE` tells what a file holds)");
  if (impl_->info.schema_version > max_schema_version)
    throw InputError("file written by a newer pdcg")
        .source(impl_->path.string())
        .key("schema_version")
        .value(std::to_string(impl_->info.schema_version))
        .expected("at most " + std::to_string(max_schema_version))
        .fix("upgrade pdcg");
}

bool H5Reader::exists(std::string_view p) const {
  const std::string s(p);
  // H5Lexists needs every intermediate link to exist; walk the path.
  std::size_t pos = 0;
  while (true) {
    pos = s.find('/', pos + 1);
    const std::string prefix = s.substr(0, pos);
    if (!prefix.empty() && prefix != "/" &&
        H5Lexists(impl_->file.get(), prefix.c_str(), H5P_DEFAULT) <= 0)
      return false;
    if (pos == std::string::npos) return true;
  }
}

std::vector<std::size_t> H5Reader::dims(std::string_view p) const {
  Handle d = impl_->dataset(p);
  Handle space(H5Dget_space(d.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> hd(static_cast<std::size_t>(std::max(rank, 0)));
  H5Sget_simple_extent_dims(space.get(), hd.data(), nullptr);
  return {hd.begin(), hd.end()};
}

namespace {
std::size_t count(const std::vector<std::size_t>& dims) {
  std::size_t n = 1;
  for (auto d : dims) n *= d;
  return n;
}
}  // namespace

std::vector<double> H5Reader::read_double(std::string_view p) const {
  Handle d = impl_->dataset(p);
  std::vector<double> out(count(dims(p)));
  if (!out.empty() &&
      H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    fail("cannot read dataset as double", impl_->path, p);
  return out;
}

std::vector<std::int64_t> H5Reader::read_int(std::string_view p) const {
  Handle d = impl_->dataset(p);
  std::vector<std::int64_t> out(count(dims(p)));
  if (!out.empty() &&
      H5Dread(d.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    fail("cannot read dataset as integer", impl_->path, p);
  return out;
}

std::string H5Reader::read_string(std::string_view p) const {
  Handle d = impl_->dataset(p);
  // H5Dread writes one pointer per element: more than one would overrun `s`
  if (const std::size_t n = count(dims(p)); n != 1)
    fail(fmt::format("expected one string, found {} elements in dataset", n), impl_->path, p);
  Handle t = string_type();
  char* s = nullptr;
  if (H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &s) < 0)
    fail("cannot read string", impl_->path, p);
  std::string out = s ? s : "";
  H5free_memory(s);
  return out;
}

std::vector<std::string> H5Reader::read_strings(std::string_view p) const {
  Handle d = impl_->dataset(p);
  Handle t = string_type();
  std::vector<char*> ptrs(count(dims(p)), nullptr);
  if (!ptrs.empty() && H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ptrs.data()) < 0)
    fail("cannot read strings", impl_->path, p);
  std::vector<std::string> out;
  out.reserve(ptrs.size());
  for (char* s : ptrs) {
    out.emplace_back(s ? s : "");
    H5free_memory(s);
  }
  return out;
}

std::vector<std::string> H5Reader::list(std::string_view group) const {
  const std::string g(group.empty() ? "/" : group);
  Handle gid(H5Gopen2(impl_->file.get(), g.c_str(), H5P_DEFAULT), H5Gclose);
  if (!gid.valid()) fail("cannot open group", impl_->path, g);
  std::vector<std::string> names;
  H5Literate(
      gid.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->emplace_back(name);
        return 0;
      },
      &names);
  return names;
}

bool H5Reader::has_attribute(std::string_view object, std::string_view name) const {
  Handle o = open_object(impl_->file.get(), object);
  const std::string n(name);
  return o.valid() && H5Aexists(o.get(), n.c_str()) > 0;
}

double H5Reader::attribute_double(std::string_view object, std::string_view name) const {
  Handle a = impl_->attr(object, name);
  double v = 0;
  if (H5Aread(a.get(), H5T_NATIVE_DOUBLE, &v) < 0) fail("cannot read attribute", impl_->path, name);
  return v;
}
std::int64_t H5Reader::attribute_int(std::string_view object, std::string_view name) const {
  Handle a = impl_->attr(object, name);
  std::int64_t v = 0;
  if (H5Aread(a.get(), H5T_NATIVE_INT64, &v) < 0) fail("cannot read attribute", impl_->path, name);
  return v;
}
std::string H5Reader::attribute_string(std::string_view object, std::string_view name) const {
  Handle a = impl_->attr(object, name);
  Handle t = string_type();
  char* s = nullptr;
  if (H5Aread(a.get(), t.get(), &s) < 0) fail("cannot read attribute", impl_->path, name);
  std::string out = s ? s : "";
  H5free_memory(s);
  return out;
}

std::string hdf5_version() {
  unsigned maj = 0, min = 0, rel = 0;
  H5get_libversion(&maj, &min, &rel);
  return fmt::format("{}.{}.{}", maj, min, rel);
}

}  // namespace pdcg::io
