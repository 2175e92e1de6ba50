#include "text_source.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>

#include "pdcg/core/error.hpp"

namespace pdcg::atomistic::detail {

namespace {

InputError cannot_open(const std::string& path, int err) {
  return InputError(err == ENOENT ? "file not found" : "cannot open file")
      .source(path)
      .value(std::strerror(err))
      .expected("a readable LAMMPS dump or data file (plain text or gzip)")
      .fix("check the path and the permissions");
}

class PlainSource final : public ByteSource {
 public:
  explicit PlainSource(const std::string& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw cannot_open(path, errno);
#ifdef POSIX_FADV_SEQUENTIAL
    ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
#endif
  }
  ~PlainSource() override {
    if (fd_ >= 0) ::close(fd_);
  }
  PlainSource(const PlainSource&) = delete;
  PlainSource& operator=(const PlainSource&) = delete;

  std::size_t read(char* dst, std::size_t n) override {
    for (;;) {
      const ssize_t got = ::read(fd_, dst, n);
      if (got >= 0) return static_cast<std::size_t>(got);
      if (errno == EINTR) continue;
      throw InputError("read error").source(path_).value(std::strerror(errno));
    }
  }
  void seek(std::uint64_t offset) override {
    if (::lseek(fd_, static_cast<off_t>(offset), SEEK_SET) < 0)
      throw InputError("cannot seek").source(path_).value(std::strerror(errno));
  }
  bool compressed() const override { return false; }

 private:
  std::string path_;
  int fd_ = -1;
};

class GzipSource final : public ByteSource {
 public:
  explicit GzipSource(const std::string& path) : path_(path) {
    gz_ = ::gzopen(path.c_str(), "rb");
    if (!gz_) throw cannot_open(path, errno ? errno : EIO);
    ::gzbuffer(gz_, 1u << 20);  // zlib's input buffer: 1 MiB instead of 8 KiB
  }
  ~GzipSource() override {
    if (gz_) ::gzclose(gz_);
  }
  GzipSource(const GzipSource&) = delete;
  GzipSource& operator=(const GzipSource&) = delete;

  std::size_t read(char* dst, std::size_t n) override {
    const unsigned want = static_cast<unsigned>(std::min<std::size_t>(n, UINT_MAX / 2));
    const int got = ::gzread(gz_, dst, want);
    if (got < 0) throw corrupt();
    if (got == 0) {
      int err = Z_OK;
      const char* msg = ::gzerror(gz_, &err);
      if (err != Z_OK && err != Z_STREAM_END) throw corrupt(msg);
    }
    return static_cast<std::size_t>(got);
  }
  void seek(std::uint64_t offset) override {
    if (::gzseek(gz_, static_cast<z_off_t>(offset), SEEK_SET) < 0) throw corrupt();
  }
  bool compressed() const override { return true; }

 private:
  InputError corrupt(const char* msg = nullptr) const {
    int err = Z_OK;
    if (!msg) msg = ::gzerror(gz_, &err);
    return InputError("corrupt or truncated gzip data")
        .source(path_)
        .value(msg ? msg : "?")
        .expected("a complete gzip stream")
        .fix("the file was cut short (disk full, run killed?); regenerate it or test it with "
             "'gzip -t'");
  }
  std::string path_;
  gzFile gz_ = nullptr;
};

}  // namespace

std::unique_ptr<ByteSource> ByteSource::open(const std::string& path) {
  unsigned char magic[2] = {0, 0};
  {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) throw cannot_open(path, errno);
    const ssize_t got = ::read(fd, magic, 2);
    ::close(fd);
    if (got < 0) throw cannot_open(path, errno);
  }
  if (magic[0] == 0x1f && magic[1] == 0x8b) return std::make_unique<GzipSource>(path);
  return std::make_unique<PlainSource>(path);
}

LineReader::LineReader(ByteSource& source, std::size_t chunk_bytes)
    : src_(source), chunk_(chunk_bytes) {
  buf_.resize(chunk_);
}

bool LineReader::refill() {
  if (eof_) return false;
  if (pos_ > 0) {
    const std::size_t keep = end_ - pos_;
    if (keep) std::memmove(buf_.data(), buf_.data() + pos_, keep);
    buf_offset_ += pos_;
    end_ = keep;
    pos_ = 0;
  }
  if (end_ == buf_.size()) buf_.resize(buf_.size() * 2);  // one line longer than the buffer
  const std::size_t got = src_.read(buf_.data() + end_, buf_.size() - end_);
  if (got == 0) {
    eof_ = true;
    return false;
  }
  end_ += got;
  return true;
}

bool LineReader::next(std::string_view& line) {
  std::size_t scanned = 0;  // bytes after pos_ already known to hold no '\n'
  for (;;) {
    const char* b = buf_.data() + pos_;
    const void* nl = std::memchr(b + scanned, '\n', end_ - pos_ - scanned);
    if (nl) {
      const std::size_t len = static_cast<std::size_t>(static_cast<const char*>(nl) - b);
      line = std::string_view(b, len);
      pos_ += len + 1;
      ++line_no_;
      return true;
    }
    scanned = end_ - pos_;
    if (!refill()) {
      if (pos_ < end_) {  // last line without a newline
        line = std::string_view(buf_.data() + pos_, end_ - pos_);
        pos_ = end_;
        ++line_no_;
        return true;
      }
      return false;
    }
  }
}

void LineReader::seek(std::uint64_t offset, long line_number) {
  if (offset >= buf_offset_ && offset <= buf_offset_ + end_) {
    pos_ = static_cast<std::size_t>(offset - buf_offset_);
  } else {
    src_.seek(offset);
    buf_offset_ = offset;
    pos_ = end_ = 0;
    eof_ = false;
  }
  line_no_ = line_number - 1;
}

}  // namespace pdcg::atomistic::detail
