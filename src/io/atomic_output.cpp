#include "pdcg/io/atomic_output.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <streambuf>
#include <string>
#include <system_error>
#include <vector>

#include "pdcg/core/error.hpp"

namespace pdcg::io {

namespace {
std::atomic<unsigned> g_counter{0};

/// ".<name>.tmp.<pid>.<n>": hidden, unique per process and writer.
std::filesystem::path temporary_for(const std::filesystem::path& final_path) {
  std::string name = ".";
  name.append(final_path.filename().string());
  name.append(".tmp.");
  name.append(std::to_string(getpid()));
  name.push_back('.');
  name.append(std::to_string(g_counter++));
  return final_path.parent_path() / name;
}

std::string fix_for(int err, const std::filesystem::path& dir) {
  const std::string d = dir.empty() ? std::string(".") : dir.string();
  switch (err) {
    case ENOSPC:
    case EDQUOT:
      return "free space on the file system of " + d + " (`df -h " + d +
             "`), or write the output elsewhere (-o/--output on another file system)";
    case EFBIG:
      return "the file exceeds the file size limit (`ulimit -f`) or the file system's largest "
             "file: raise the limit (`ulimit -f unlimited`) or write the output elsewhere "
             "(-o/--output)";
    case EROFS:
    case EACCES:
    case EPERM:
      return "write the output to a writable directory (-o/--output), or make " + d + " writable";
    case EIO:
      return "the device reported an I/O error: check the disk (dmesg), write the output "
             "elsewhere (-o/--output)";
    default:
      return "check " + d + ", or write the output elsewhere (-o/--output)";
  }
}

/// Best effort: a rename is durable once its directory is synced.
void sync_directory(const std::filesystem::path& dir) {
  const std::string d = dir.empty() ? std::string(".") : dir.string();
  const int fd = ::open(d.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

void make_parent(const std::filesystem::path& final_path, std::string_view option) {
  const auto dir = final_path.parent_path();
  if (dir.empty() || std::filesystem::is_directory(dir)) return;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    InputError e("cannot create the output directory");
    if (!option.empty()) e.source(option);
    throw e.value(dir.string())
        .expected("a directory that exists or can be created")
        .fix(ec.message() + ": choose another location, or create it (mkdir -p " + dir.string() +
             ")");
  }
}

/// std::streambuf on a file descriptor that remembers the first write error (errno).
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd), buf_(1 << 16) { setp(buf_.data(), buf_.data() + buf_.size()); }
  int error() const { return error_; }
  bool drain() {
    const char* p = pbase();
    std::size_t n = static_cast<std::size_t>(pptr() - pbase());
    while (n > 0 && error_ == 0) {
      const ssize_t w = ::write(fd_, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        break;
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    setp(buf_.data(), buf_.data() + buf_.size());
    return error_ == 0;
  }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  int fd_;
  std::vector<char> buf_;
  int error_ = 0;
};

}  // namespace

void throw_write_error(const std::filesystem::path& final_path, int err, std::string_view during) {
  throw Error("cannot write " + final_path.string() + ": " + std::strerror(err) + " (errno " +
              std::to_string(err) + ") while " + std::string(during) +
              "; nothing was written under that name (an earlier version of it, and every "
              "earlier output, is intact). Fix: " +
              fix_for(err, final_path.parent_path()));
}

AtomicPath::AtomicPath(std::filesystem::path final_path) : final_(std::move(final_path)) {
  if (final_.filename().empty())
    throw InputError("output path names a directory, not a file")
        .value(final_.string())
        .expected("a file name")
        .fix("add a file name, e.g. out/result.h5");
  make_parent(final_, {});
  temporary_ = temporary_for(final_);
}

AtomicPath::~AtomicPath() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temporary_, ec);
  }
}

void AtomicPath::commit() {
  // fsync before the rename: errors the file system reports late (delayed allocation,
  // network file systems) surface here, and the final name never points at lost data.
  const int fd = ::open(temporary_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw_write_error(final_, errno, "reopening the temporary " + temporary_.string());
  if (::fsync(fd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(fd);
    throw_write_error(final_, err, "syncing the temporary " + temporary_.string());
  }
  ::close(fd);
  std::error_code ec;
  std::filesystem::rename(temporary_, final_, ec);
  if (ec) throw_write_error(final_, ec.value(), "renaming the temporary " + temporary_.string());
  committed_ = true;
  sync_directory(final_.parent_path());
}

// ---------------------------------------------------------------- text files

struct AtomicTextFile::Impl {
  AtomicPath path;  // declared first: destroyed last, after the descriptor is closed
  int fd = -1;
  int open_error = 0;
  FdBuf buf;
  std::ostream stream;
  explicit Impl(std::filesystem::path p)
      : path(std::move(p)),
        fd(::open(path.temporary().c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666)),
        open_error(fd < 0 ? errno : 0),
        buf(fd),
        stream(&buf) {}
  ~Impl() {
    if (fd >= 0) ::close(fd);  // path's destructor then removes the temporary
  }
};

AtomicTextFile::AtomicTextFile(std::filesystem::path final_path)
    : impl_(std::make_unique<Impl>(final_path)) {
  if (impl_->fd < 0) {
    const int err = impl_->open_error;
    throw InputError("cannot create output file")
        .value(final_path.string())
        .expected("a writable location")
        .fix(std::string(std::strerror(err)) + ": " + fix_for(err, final_path.parent_path()));
  }
  impl_->stream.precision(17);
}

AtomicTextFile::~AtomicTextFile() = default;
AtomicTextFile::AtomicTextFile(AtomicTextFile&&) noexcept = default;

std::ostream& AtomicTextFile::stream() { return impl_->stream; }

void AtomicTextFile::commit() {
  auto& m = *impl_;
  m.stream.flush();
  if (m.buf.error() != 0)
    throw_write_error(m.path.final_path(), m.buf.error(),
                      "writing the temporary " + m.path.temporary().string());
  if (!m.stream) throw Error("output stream error on " + m.path.temporary().string());
  const int fd = m.fd;
  m.fd = -1;
  if (::close(fd) != 0)
    throw_write_error(m.path.final_path(), errno,
                      "closing the temporary " + m.path.temporary().string());
  m.path.commit();
}

// ---------------------------------------------------------------- checks

namespace {
void check_directory(const std::filesystem::path& dir, std::string_view option,
                     const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec)) {
    InputError e("the output directory is an existing file");
    if (!option.empty()) e.source(option);
    throw e.value(dir.string()).expected("a directory").fix("choose another output directory");
  }
  make_parent(dir / "x", option);
  const auto probe = temporary_for(dir / ".pdcg-probe");
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  int err = fd < 0 ? errno : 0;
  if (fd >= 0) {
    // one byte: a file system that is already full refuses it now, not after the computation
    if (::write(fd, "x", 1) != 1) err = errno;
    ::close(fd);
    ::unlink(probe.c_str());
  }
  if (err != 0) {
    InputError e(file.empty() ? "cannot write in the output directory"
                              : "cannot write " + file.string() + " in its directory");
    if (!option.empty()) e.source(option);
    throw e.value(dir.string())
        .expected("a writable directory with free space")
        .fix(std::string(std::strerror(err)) + ": " + fix_for(err, dir));
  }
}

}  // namespace

void require_writable_directory(const std::filesystem::path& dir, std::string_view option) {
  check_directory(dir, option, {});
}

void require_writable_output(const std::filesystem::path& file, std::string_view option) {
  std::error_code ec;
  if (file.filename().empty() || std::filesystem::is_directory(file, ec)) {
    InputError e("the output names a directory, not a file");
    if (!option.empty()) e.source(option);
    throw e.value(file.string()).expected("a file name").fix("add a file name, e.g. out/result.h5");
  }
  const auto dir = file.parent_path();
  check_directory(dir.empty() ? std::filesystem::path(".") : dir, option, file);
}

int remove_stale_temporaries(const std::filesystem::path& dir) {
  int removed = 0;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name[0] != '.') continue;
    const auto t = name.rfind(".tmp.");
    if (t == std::string::npos) continue;
    const std::string rest = name.substr(t + 5);  // <pid>.<n>
    const auto dot = rest.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == rest.size() ||
        rest.find_first_not_of("0123456789.") != std::string::npos ||
        rest.find('.', dot + 1) != std::string::npos)
      continue;
    const long pid = std::stol(rest.substr(0, dot));
    if (pid <= 0 || pid == static_cast<long>(getpid())) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // alive (or not ours)
    std::error_code rc;
    if (std::filesystem::remove(it->path(), rc)) ++removed;
  }
  return removed;
}

}  // namespace pdcg::io
