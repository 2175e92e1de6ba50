#include "pdcg/io/hdf5.hpp"

#include <fmt/format.h>
#include <hdf5.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>

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
  hid_t release() {
    const hid_t id = id_;
    id_ = -1;
    return id;
  }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

/// Silences HDF5's own error stack printing; we report errors ourselves. No atexit clean-up:
/// a file whose close failed (full disk) stays open inside HDF5, and HDF5 1.10's clean-up at
/// exit flushes it again and crashes (SIGSEGV in H5F__close_cb). Every file pdcg opens is
/// closed by its owner; the one that could not be is abandoned (its temporary is unlinked).
struct QuietHdf5 {
  QuietHdf5() {
    H5dont_atexit();  // before any other HDF5 call
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
};
const QuietHdf5 g_quiet;

/// The messages of HDF5's error stack (innermost last), and the errno it recorded (0: none).
struct Hdf5Failure {
  std::string text;
  int os_error = 0;
};
Hdf5Failure hdf5_failure() {
  Hdf5Failure f;
  const int saved = errno;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* e, void* data) -> herr_t {
        auto& out = *static_cast<Hdf5Failure*>(data);
        if (!e->desc) return 0;
        const std::string d = e->desc;
        if (!out.text.empty()) out.text += "; ";
        out.text += d;
        const auto k = d.find("errno = ");
        if (k != std::string::npos && out.os_error == 0)
          out.os_error = std::atoi(d.c_str() + k + 8);
        return 0;
      },
      &f);
  if (f.os_error == 0 &&
      (saved == ENOSPC || saved == EFBIG || saved == EDQUOT || saved == EIO || saved == EROFS))
    f.os_error = saved;
  return f;
}

/// Writer side: an OS error (full disk, file size limit, ...) becomes the clear write error.
[[noreturn]] void fail_write(std::string_view what, const AtomicPath& file, std::string_view path) {
  const auto f = hdf5_failure();
  if (f.os_error != 0)
    throw_write_error(file.final_path(), f.os_error,
                      fmt::format("{} '{}' (temporary {})", what, path, file.temporary().string()));
  throw Error(fmt::format("HDF5 failed {} '{}' of {} (temporary {}){}", what, path,
                          file.final_path().string(), file.temporary().string(),
                          f.text.empty() ? std::string() : " (" + f.text + ")"));
}

/// Writer side, in memory: no OS error to report (the core driver allocates).
[[noreturn]] void fail_write(std::string_view what, std::string_view memory_name,
                             std::string_view path) {
  const auto f = hdf5_failure();
  throw Error(fmt::format("HDF5 failed {} '{}' of the in-memory file {}{}", what, path, memory_name,
                          f.text.empty() ? std::string() : " (" + f.text + ")"));
}

/// A file-access property list for a file that lives in memory only: HDF5's core driver
/// without a backing store, growing by 64 KiB; with `image`, the file starts as a copy of it.
Handle in_memory_access(std::span<const unsigned char> image = {}) {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (!fapl.valid() || H5Pset_fapl_core(fapl.get(), 64 * 1024, 0) < 0 ||
      (!image.empty() &&
       H5Pset_file_image(fapl.get(), const_cast<unsigned char*>(image.data()), image.size()) < 0))
    throw Error("HDF5 cannot set up an in-memory file (core driver)");
  return fapl;
}

/// The name under which HDF5 holds an in-memory file: unique in the process, since the core
/// driver takes two open files of one name for the same file (the name in messages is the
/// caller's).
std::string core_driver_name() {
  static std::atomic<unsigned long long> next{0};
  return fmt::format("pdcg-in-memory-{}", next++);
}

/// Reader side: a file that HDF5 cannot read is damaged (truncated, overwritten): InputError.
[[noreturn]] void fail_read(std::string_view what, const std::filesystem::path& file,
                            std::string_view path) {
  const auto f = hdf5_failure();
  throw InputError(fmt::format("{} '{}': the file is truncated or corrupt", what, path))
      .source(file.string())
      .expected(f.text.empty() ? std::string("a complete HDF5 file")
                               : "a complete HDF5 file (HDF5: " + f.text + ")")
      .fix("write the file again (an incomplete copy, a full disk or a disk error damaged it)");
}

/// CRC-32 (zlib) of bytes, continuing from crc.
std::uint32_t crc_of(const void* data, std::size_t n, std::uint32_t crc = 0) {
  const auto* p = static_cast<const Bytef*>(data);
  uLong c = crc;
  while (n > 0) {
    const uInt k = static_cast<uInt>(std::min<std::size_t>(n, 1u << 30));
    c = crc32(c, p, k);
    p += k;
    n -= k;
  }
  return static_cast<std::uint32_t>(c);
}
std::uint32_t crc_of_strings(const std::vector<std::string>& v) {
  std::uint32_t c = 0;
  for (const auto& s : v) c = crc_of(s.data(), s.size() + 1, c);  // with the terminating NUL
  return c;
}

constexpr const char* kCrc = "crc32";

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
  std::optional<AtomicPath> disk;  ///< on disk: the temporary and the final path
  std::string memory_name;         ///< in memory: the name in messages
  std::optional<H5Image> image;    ///< in memory: the file, after commit()
  Handle file;
  Handle link_props;

  [[noreturn]] void fail(std::string_view what, std::string_view dpath) const {
    if (disk) fail_write(what, *disk, dpath);
    fail_write(what, memory_name, dpath);
  }
  /// After the file is open: the link properties and the root's identification.
  void start(H5Writer& w, FileInfo& info);

  void write_array(std::string_view dpath, hid_t memtype, const void* data, std::size_t size,
                   std::vector<std::size_t> dims) {
    if (dims.empty()) dims = {size};
    std::size_t n = 1;
    for (auto d : dims) n *= d;
    if (n != size)
      throw Error(
          fmt::format("HDF5 write '{}': {} values do not fill dims of {} values", dpath, size, n));
    std::vector<hsize_t> hd(dims.begin(), dims.end());
    Handle space(H5Screate_simple(static_cast<int>(hd.size()), hd.data(), nullptr), H5Sclose);
    const std::string p(dpath);
    Handle set(H5Dcreate2(file.get(), p.c_str(), memtype, space.get(), link_props.get(),
                          H5P_DEFAULT, H5P_DEFAULT),
               H5Dclose);
    if (!set.valid()) fail("creating dataset", dpath);
    if (n > 0 && H5Dwrite(set.get(), memtype, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
      fail("writing dataset", dpath);
    put_crc(set.get(), dpath, crc_of(data, n * H5Tget_size(memtype)));
  }

  /// crc32 attribute of a dataset: CRC-32 of its values in memory (native byte order) or of
  /// its strings with their NULs; H5Reader verifies it on every read.
  void put_crc(hid_t set, std::string_view dpath, std::uint32_t crc) {
    const std::int64_t v = crc;
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    Handle a(H5Acreate2(set, kCrc, H5T_STD_I64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (!a.valid() || H5Awrite(a.get(), H5T_NATIVE_INT64, &v) < 0)
      fail("writing the checksum of", dpath);
  }

  Handle object_for_attribute(std::string_view object) {
    Handle o = open_object(file.get(), object);
    if (!o.valid()) {
      // create the group if it does not exist yet
      const std::string p(object);
      Handle g(H5Gcreate2(file.get(), p.c_str(), link_props.get(), H5P_DEFAULT, H5P_DEFAULT),
               H5Gclose);
      if (!g.valid()) fail("creating group", object);
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
    Handle a(H5Acreate2(o.get(), n.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    if (!a.valid() || H5Awrite(a.get(), type, value) < 0)
      fail("writing attribute", std::string(object) + "@" + n);
  }
};

H5Writer::H5Writer(std::filesystem::path final_path, FileInfo info)
    : impl_(std::make_unique<Impl>()) {
  const AtomicPath& disk = impl_->disk.emplace(std::move(final_path));
  impl_->file = Handle(H5Fcreate(disk.temporary().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                       H5Fclose);
  if (!impl_->file.valid()) {
    const auto f = hdf5_failure();
    throw InputError("cannot create HDF5 file")
        .value(disk.final_path().string())
        .expected("a writable location")
        .fix(f.os_error != 0 ? std::string(std::strerror(f.os_error)) +
                                   ": write the output to a writable directory with free "
                                   "space (-o/--output)"
                             : "check that the directory exists and is writable");
  }
  impl_->start(*this, info);
}

H5Writer::H5Writer(InMemory file, FileInfo info) : impl_(std::make_unique<Impl>()) {
  impl_->memory_name = std::move(file.name);
  const Handle fapl = in_memory_access();
  impl_->file = Handle(
      H5Fcreate(core_driver_name().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose);
  if (!impl_->file.valid()) fail_write("creating", impl_->memory_name, "/");
  impl_->start(*this, info);
}

void H5Writer::Impl::start(H5Writer& w, FileInfo& info) {
  link_props = Handle(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(link_props.get(), 1);
  if (info.pdcg_version.empty()) info.pdcg_version = pdcg::version();
  if (info.command_line.empty()) info.command_line = pdcg::command_line();
  w.attribute("/", "format", info.format);
  w.attribute("/", "schema_version", static_cast<std::int64_t>(info.schema_version));
  w.attribute("/", "pdcg_version", info.pdcg_version);
  w.attribute("/", "units", to_string(info.units));
  w.attribute("/", "command_line", info.command_line);
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
  Handle set(H5Dcreate2(impl_->file.get(), p.c_str(), t.get(), space.get(), impl_->link_props.get(),
                        H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!set.valid() || H5Dwrite(set.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &cs) < 0)
    impl_->fail("writing string", path);
  impl_->put_crc(set.get(), path, crc_of(s.data(), s.size()));
}
void H5Writer::write_strings(std::string_view path, const std::vector<std::string>& lines) {
  Handle t = string_type();
  hsize_t n = lines.size();
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  std::vector<const char*> ptrs;
  ptrs.reserve(lines.size());
  for (const auto& l : lines) ptrs.push_back(l.c_str());
  const std::string p(path);
  Handle set(H5Dcreate2(impl_->file.get(), p.c_str(), t.get(), space.get(), impl_->link_props.get(),
                        H5P_DEFAULT, H5P_DEFAULT),
             H5Dclose);
  if (!set.valid() ||
      (n > 0 && H5Dwrite(set.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ptrs.data()) < 0))
    impl_->fail("writing strings", path);
  impl_->put_crc(set.get(), path, crc_of_strings(lines));
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
  if (H5Fflush(impl_->file.get(), H5F_SCOPE_GLOBAL) < 0) impl_->fail("flushing", "/");
  if (!impl_->disk) {  // in memory: the bytes before the file (and with it the memory) closes
    const ssize_t n = H5Fget_file_image(impl_->file.get(), nullptr, 0);
    H5Image bytes(n > 0 ? static_cast<std::size_t>(n) : 0);
    if (n <= 0 || H5Fget_file_image(impl_->file.get(), bytes.data(), bytes.size()) != n)
      impl_->fail("taking the image of", "/");
    if (H5Fclose(impl_->file.release()) < 0) impl_->fail("closing", "/");
    impl_->image = std::move(bytes);
    return;
  }
  if (H5Fclose(impl_->file.release()) < 0) impl_->fail("closing", "/");
  impl_->disk->commit();
}

const H5Image& H5Writer::image() const {
  if (!impl_->image)
    throw std::logic_error(impl_->disk ? "H5Writer::image() of a writer to a file"
                                       : "H5Writer::image() before commit()");
  return *impl_->image;
}

// ---------------------------------------------------------------- reader

struct H5Reader::Impl {
  std::filesystem::path path;  ///< in memory: the caller's name
  Handle file;
  FileInfo info;

  /// After H5Fopen: refuses a file HDF5 could not open, reads the root's identification.
  void start(const H5Reader& r);

  Handle dataset(std::string_view p) const {
    const std::string s(p);
    if (H5Lexists(file.get(), s.c_str(), H5P_DEFAULT) <= 0)
      throw InputError("missing dataset")
          .source(path.string())
          .key(p)
          .expected("a pdcg file that holds it")
          .fix("check the file kind with `pdcg info`");
    Handle d(H5Dopen2(file.get(), s.c_str(), H5P_DEFAULT), H5Dclose);
    if (!d.valid()) fail_read("cannot open dataset", path, p);
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

  /// Compares the dataset's crc32 attribute (if it has one) with crc.
  void verify_crc(hid_t d, std::string_view p, std::uint32_t crc) const {
    if (H5Aexists(d, kCrc) <= 0) return;  // written before checksums, or by another program
    Handle a(H5Aopen(d, kCrc, H5P_DEFAULT), H5Aclose);
    std::int64_t stored = -1;
    if (!a.valid() || H5Aread(a.get(), H5T_NATIVE_INT64, &stored) < 0)
      fail_read("cannot read the checksum of", path, p);
    if (static_cast<std::uint32_t>(stored) != crc || stored < 0 || stored > 0xffffffffLL)
      throw InputError(fmt::format("dataset '{}' fails its checksum: the file is corrupt", p))
          .source(path.string())
          .value(fmt::format("CRC-32 {:08x}", crc))
          .expected(fmt::format("{:08x} (stored when the file was written)",
                                static_cast<std::uint32_t>(stored)))
          .fix("write the file again (a disk error, an incomplete copy or an edit damaged it)");
  }
  /// Verifies values read as memtype: directly when memtype is the stored (native) type,
  /// else by reading the stored values once more in their own type.
  void verify(hid_t d, std::string_view p, const void* data, std::size_t bytes,
              hid_t memtype) const {
    if (H5Aexists(d, kCrc) <= 0) return;
    Handle ft(H5Dget_type(d), H5Tclose);
    Handle nt(H5Tget_native_type(ft.get(), H5T_DIR_ASCEND), H5Tclose);
    if (H5Tequal(nt.get(), memtype) > 0) return verify_crc(d, p, crc_of(data, bytes));
    verify_raw(d, p);
  }
  /// Reads a dataset in its stored type and verifies its checksum.
  void verify_raw(hid_t d, std::string_view p) const {
    if (H5Aexists(d, kCrc) <= 0) return;
    Handle ft(H5Dget_type(d), H5Tclose);
    Handle space(H5Dget_space(d), H5Sclose);
    const auto n = static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get()));
    if (H5Tget_class(ft.get()) == H5T_STRING) {
      Handle t = string_type();
      std::vector<char*> ptrs(std::max<std::size_t>(n, 1), nullptr);
      if (n > 0 && H5Dread(d, t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ptrs.data()) < 0)
        fail_read("cannot read strings", path, p);
      std::vector<std::string> v;
      for (std::size_t i = 0; i < n; ++i) {
        v.emplace_back(ptrs[i] ? ptrs[i] : "");
        H5free_memory(ptrs[i]);
      }
      const bool scalar = H5Sget_simple_extent_type(space.get()) == H5S_SCALAR;
      return verify_crc(d, p, scalar ? crc_of(v[0].data(), v[0].size()) : crc_of_strings(v));
    }
    Handle nt(H5Tget_native_type(ft.get(), H5T_DIR_ASCEND), H5Tclose);
    std::vector<unsigned char> buf(n * H5Tget_size(nt.get()));
    if (n > 0 && H5Dread(d, nt.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) < 0)
      fail_read("cannot read dataset", path, p);
    verify_crc(d, p, crc_of(buf.data(), buf.size()));
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
        .fix(
            "pass a file written by pdcg (a file cut short before its first bytes, e.g. by a "
            "full disk, also ends here: write it again)");
  impl_->file = Handle(H5Fopen(impl_->path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  impl_->start(*this);
}

namespace {
/// What H5Fis_hdf5 checks of a file, for an image: the superblock signature at byte 0, 512,
/// 1024, 2048, … (HDF5 File Format Specification, "Format Signature").
bool has_hdf5_signature(std::span<const unsigned char> image) {
  static constexpr unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
  for (std::size_t at = 0; at + sizeof sig <= image.size(); at = at == 0 ? 512 : 2 * at)
    if (std::memcmp(image.data() + at, sig, sizeof sig) == 0) return true;
  return false;
}
}  // namespace

H5Reader::H5Reader(InMemory file, std::span<const unsigned char> image)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = std::move(file.name);
  if (!has_hdf5_signature(image))
    throw InputError("not an HDF5 file")
        .value(impl_->path.string())
        .expected("a pdcg HDF5 file (.h5)")
        .fix("pass a file written by pdcg");
  const Handle fapl = in_memory_access(image);
  impl_->file = Handle(H5Fopen(core_driver_name().c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose);
  impl_->start(*this);
}

void H5Reader::Impl::start(const H5Reader& r) {
  if (!file.valid()) {
    const auto f = hdf5_failure();
    throw InputError("HDF5 file that cannot be opened: truncated or corrupt")
        .value(path.string())
        .expected(f.text.empty() ? std::string("a complete HDF5 file")
                                 : "a complete HDF5 file (HDF5: " + f.text + ")")
        .fix("write the file again (an incomplete copy, a full disk or a disk error damaged it)");
  }
  if (!r.has_attribute("/", "format"))
    throw InputError("HDF5 file without a pdcg 'format' attribute")
        .value(path.string())
        .expected("a file written by pdcg")
        .fix("pass a file written by pdcg");
  info.format = r.attribute_string("/", "format");
  info.schema_version = static_cast<int>(r.attribute_int("/", "schema_version"));
  info.pdcg_version = r.attribute_string("/", "pdcg_version");
  info.units = parse_unit_style(r.attribute_string("/", "units"), path.string());
  info.command_line = r.attribute_string("/", "command_line");
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

namespace {
std::vector<std::size_t> dims_of(hid_t dataset) {
  Handle space(H5Dget_space(dataset), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> hd(static_cast<std::size_t>(std::max(rank, 0)));
  H5Sget_simple_extent_dims(space.get(), hd.data(), nullptr);
  return {hd.begin(), hd.end()};
}
/// Number of elements of an open dataset.
std::size_t count(hid_t dataset) {
  std::size_t n = 1;
  for (auto d : dims_of(dataset)) n *= d;
  return n;
}
}  // namespace

std::vector<std::size_t> H5Reader::dims(std::string_view p) const {
  return dims_of(impl_->dataset(p).get());
}

std::vector<double> H5Reader::read_double(std::string_view p) const {
  Handle d = impl_->dataset(p);
  std::vector<double> out(count(d.get()));
  if (!out.empty() &&
      H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    fail_read("cannot read dataset", impl_->path, p);
  impl_->verify(d.get(), p, out.data(), out.size() * sizeof(double), H5T_NATIVE_DOUBLE);
  return out;
}

std::vector<std::int64_t> H5Reader::read_int(std::string_view p) const {
  Handle d = impl_->dataset(p);
  std::vector<std::int64_t> out(count(d.get()));
  if (!out.empty() &&
      H5Dread(d.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    fail_read("cannot read dataset", impl_->path, p);
  impl_->verify(d.get(), p, out.data(), out.size() * sizeof(std::int64_t), H5T_NATIVE_INT64);
  return out;
}

std::string H5Reader::read_string(std::string_view p) const {
  Handle d = impl_->dataset(p);
  // H5Dread writes one pointer per element: more than one would overrun `s`
  if (const std::size_t n = count(d.get()); n != 1)
    throw InputError(fmt::format("expected one string, found {} elements in dataset '{}'", n, p))
        .source(impl_->path.string())
        .fix("the file was not written by pdcg, or is damaged: write it again");
  Handle t = string_type();
  char* s = nullptr;
  if (H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &s) < 0)
    fail_read("cannot read string", impl_->path, p);
  std::string out = s ? s : "";
  H5free_memory(s);
  impl_->verify_crc(d.get(), p, crc_of(out.data(), out.size()));
  return out;
}

std::vector<std::string> H5Reader::read_strings(std::string_view p) const {
  Handle d = impl_->dataset(p);
  Handle t = string_type();
  std::vector<char*> ptrs(count(d.get()), nullptr);
  if (!ptrs.empty() && H5Dread(d.get(), t.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, ptrs.data()) < 0)
    fail_read("cannot read strings", impl_->path, p);
  std::vector<std::string> out;
  out.reserve(ptrs.size());
  for (char* s : ptrs) {
    out.emplace_back(s ? s : "");
    H5free_memory(s);
  }
  impl_->verify_crc(d.get(), p, crc_of_strings(out));
  return out;
}

void H5Reader::verify() const {
  std::vector<std::string> sets;
  if (H5Ovisit2(
          impl_->file.get(), H5_INDEX_NAME, H5_ITER_INC,
          [](hid_t, const char* name, const H5O_info_t* info, void* data) -> herr_t {
            if (info->type == H5O_TYPE_DATASET)
              static_cast<std::vector<std::string>*>(data)->emplace_back(name);
            return 0;
          },
          &sets, H5O_INFO_BASIC) < 0)
    fail_read("cannot list the objects of", impl_->path, "/");
  for (const auto& p : sets) {
    Handle d = impl_->dataset(p);
    impl_->verify_raw(d.get(), p);
  }
}

std::vector<std::string> H5Reader::list(std::string_view group) const {
  const std::string g(group.empty() ? "/" : group);
  Handle gid(H5Gopen2(impl_->file.get(), g.c_str(), H5P_DEFAULT), H5Gclose);
  if (!gid.valid()) fail_read("cannot open group", impl_->path, g);
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
  if (H5Aread(a.get(), H5T_NATIVE_DOUBLE, &v) < 0)
    fail_read("cannot read attribute", impl_->path, name);
  return v;
}
std::int64_t H5Reader::attribute_int(std::string_view object, std::string_view name) const {
  Handle a = impl_->attr(object, name);
  std::int64_t v = 0;
  if (H5Aread(a.get(), H5T_NATIVE_INT64, &v) < 0)
    fail_read("cannot read attribute", impl_->path, name);
  return v;
}
std::string H5Reader::attribute_string(std::string_view object, std::string_view name) const {
  Handle a = impl_->attr(object, name);
  Handle t = string_type();
  char* s = nullptr;
  if (H5Aread(a.get(), t.get(), &s) < 0) fail_read("cannot read attribute", impl_->path, name);
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
