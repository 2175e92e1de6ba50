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

/// gzip with random access (the method of zlib's examples/zran.c, Mark Adler):
/// while the file is decompressed forward, an access point is recorded at the
/// first deflate block boundary after every kSpan bytes of output — the
/// compressed offset, the bit offset inside that byte, and the last 32 KiB of
/// output (the dictionary a raw inflate needs to resume there). seek() restarts
/// a raw inflate at the last access point before the target and decompresses at
/// most kSpan bytes to reach it; seeking forward just decompresses forward.
/// Concatenated gzip members are followed; trailing bytes that are not a gzip
/// header end the stream (as gzread does).
class GzipSource final : public ByteSource {
 public:
  static constexpr std::size_t kWindow = 32768;
  static constexpr std::uint64_t kSpan = std::uint64_t{4} << 20;

  explicit GzipSource(const std::string& path) : path_(path), in_(kInChunk) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw cannot_open(path, errno);
    if (::inflateInit2(&strm_, 31) != Z_OK) throw corrupt("zlib initialisation failed");
    next_point_ = 0;
  }
  ~GzipSource() override {
    ::inflateEnd(&strm_);
    if (fd_ >= 0) ::close(fd_);
  }
  GzipSource(const GzipSource&) = delete;
  GzipSource& operator=(const GzipSource&) = delete;

  std::size_t read(char* dst_chars, std::size_t n) override {
    auto* dst = reinterpret_cast<unsigned char*>(dst_chars);
    n = std::min<std::size_t>(n, std::size_t{1} << 30);
    std::size_t produced = 0;
    while (produced < n && !end_) {
      if (strm_.avail_in == 0 && !ensure_input(1))
        throw corrupt("unexpected end of file (the gzip stream is incomplete)");
      strm_.next_out = dst + produced;
      strm_.avail_out = static_cast<uInt>(n - produced);
      const int ret = ::inflate(&strm_, Z_BLOCK);
      const std::size_t got = (n - produced) - strm_.avail_out;
      produced += got;
      out_ += got;
      if (ret == Z_NEED_DICT || ret == Z_DATA_ERROR || ret == Z_MEM_ERROR || ret == Z_STREAM_ERROR)
        throw corrupt(strm_.msg ? strm_.msg : "inflate failed");
      if (ret == Z_STREAM_END) {
        next_member();
        continue;
      }
      if ((strm_.data_type & 128) && !(strm_.data_type & 64) && out_ >= next_point_ &&
          (points_.empty() || out_ > points_.back().out))
        add_point(dst, produced);
    }
    remember_tail(dst, produced);
    return produced;
  }

  void seek(std::uint64_t offset) override {
    if (offset == out_) return;
    // The last access point at or before the target.
    const Point* p = nullptr;
    for (const auto& q : points_)
      if (q.out <= offset) p = &q;
    const bool forward_is_best = offset > out_ && (!p || p->out <= out_);
    if (!forward_is_best) {
      if (p)
        restart_at(*p);
      else
        restart_at_beginning();
    }
    skip(offset - out_);
  }
  bool compressed() const override { return true; }

 private:
  static constexpr std::size_t kInChunk = std::size_t{1} << 18;
  struct Point {
    std::uint64_t out = 0;  // uncompressed offset
    std::uint64_t in = 0;   // compressed offset of the first byte not yet fully consumed
    int bits = 0;           // unused bits of the byte before `in`
    std::vector<unsigned char> window;  // last kWindow bytes of output before `out`
  };

  /// Makes at least k input bytes available; false at end of file.
  bool ensure_input(std::size_t k) {
    if (strm_.avail_in >= k) return true;
    if (strm_.avail_in > 0 && strm_.next_in != in_.data())
      std::memmove(in_.data(), strm_.next_in, strm_.avail_in);
    strm_.next_in = in_.data();
    while (strm_.avail_in < k) {
      const ssize_t got = ::read(fd_, in_.data() + strm_.avail_in, in_.size() - strm_.avail_in);
      if (got < 0) {
        if (errno == EINTR) continue;
        throw InputError("read error").source(path_).value(std::strerror(errno));
      }
      if (got == 0) return false;
      strm_.avail_in += static_cast<uInt>(got);
      file_pos_ += static_cast<std::uint64_t>(got);
    }
    return true;
  }

  /// After the end of a member: skip its trailer (raw mode), then follow a next member if any.
  void next_member() {
    if (raw_) {
      if (!ensure_input(8)) throw corrupt("unexpected end of file in the gzip trailer");
      strm_.next_in += 8;
      strm_.avail_in -= 8;
    }
    if (!ensure_input(2) || strm_.next_in[0] != 0x1f || strm_.next_in[1] != 0x8b) {
      end_ = true;
      return;
    }
    ::inflateReset2(&strm_, 31);
    raw_ = false;
  }

  void add_point(const unsigned char* dst, std::size_t produced) {
    Point p;
    p.out = out_;
    p.in = file_pos_ - strm_.avail_in;
    p.bits = strm_.data_type & 7;
    p.window.assign(kWindow, 0);
    // The last kWindow bytes: from this call's output, completed by the previous tail.
    const std::size_t from_dst = std::min(produced, kWindow);
    std::memcpy(p.window.data() + kWindow - from_dst, dst + produced - from_dst, from_dst);
    const std::size_t from_tail = std::min(kWindow - from_dst, tail_.size());
    if (from_tail > 0)  // an empty tail has data() == nullptr: memcpy from it is undefined
      std::memcpy(p.window.data() + kWindow - from_dst - from_tail,
                  tail_.data() + tail_.size() - from_tail, from_tail);
    points_.push_back(std::move(p));
    next_point_ = out_ + kSpan;
  }

  void remember_tail(const unsigned char* dst, std::size_t produced) {
    if (produced >= kWindow) {
      tail_.assign(dst + produced - kWindow, dst + produced);
    } else {
      tail_.insert(tail_.end(), dst, dst + produced);
      if (tail_.size() > kWindow) tail_.erase(tail_.begin(), tail_.end() - kWindow);
    }
  }

  void reposition(std::uint64_t file_offset) {
    if (::lseek(fd_, static_cast<off_t>(file_offset), SEEK_SET) < 0)
      throw InputError("cannot seek").source(path_).value(std::strerror(errno));
    file_pos_ = file_offset;
    strm_.next_in = in_.data();
    strm_.avail_in = 0;
    end_ = false;
  }

  void restart_at_beginning() {
    reposition(0);
    ::inflateReset2(&strm_, 31);
    raw_ = false;
    out_ = 0;
    tail_.clear();
  }

  void restart_at(const Point& p) {
    reposition(p.in - (p.bits ? 1 : 0));
    ::inflateReset2(&strm_, -15);
    raw_ = true;
    if (p.bits) {
      if (!ensure_input(1)) throw corrupt("file shorter than its index");
      const int byte = strm_.next_in[0];
      ++strm_.next_in;
      --strm_.avail_in;
      ::inflatePrime(&strm_, p.bits, byte >> (8 - p.bits));
    }
    ::inflateSetDictionary(&strm_, p.window.data(), static_cast<uInt>(kWindow));
    out_ = p.out;
    tail_ = p.window;
  }

  void skip(std::uint64_t n) {
    std::vector<char> scratch(static_cast<std::size_t>(std::min<std::uint64_t>(n, 1u << 20)));
    while (n > 0) {
      const std::size_t got = read(
          scratch.data(), static_cast<std::size_t>(std::min<std::uint64_t>(n, scratch.size())));
      if (got == 0) throw corrupt("seek beyond the end of the data");
      n -= got;
    }
  }

  InputError corrupt(const char* msg) const {
    return InputError("corrupt or truncated gzip data")
        .source(path_)
        .value(msg)
        .expected("a complete gzip stream")
        .fix(
            "the file was cut short (disk full, run killed?); regenerate it or test it with "
            "'gzip -t'");
  }

  std::string path_;
  int fd_ = -1;
  z_stream strm_{};
  std::vector<unsigned char> in_;
  std::uint64_t file_pos_ = 0;  // file offset just past the input read so far
  std::uint64_t out_ = 0;       // uncompressed offset of the next byte read() returns
  std::uint64_t next_point_ = 0;
  bool raw_ = false, end_ = false;
  std::vector<Point> points_;
  std::vector<unsigned char> tail_;  // last ≤ kWindow bytes returned before out_
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
  buf_.resize(std::min(chunk_, kInitialBytes));
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
  if (end_ == buf_.size()) {
    buf_.resize(buf_.size() * 2);  // one line longer than the buffer
  } else if (buf_.size() < chunk_ && streamed_ >= buf_.size()) {
    // a buffer's worth read since the last growth: a larger file, larger reads (a small file,
    // or seeks within one, never grow it)
    buf_.resize(std::min(chunk_, buf_.size() * 2));
    streamed_ = 0;
  }
  const std::size_t got = src_.read(buf_.data() + end_, buf_.size() - end_);
  if (got == 0) {
    eof_ = true;
    return false;
  }
  end_ += got;
  streamed_ += got;
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
