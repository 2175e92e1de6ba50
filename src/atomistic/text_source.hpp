/// \file
/// Private to the atomistic module: byte sources (plain files through POSIX
/// read(), gzip files through zlib) and a buffered line reader on top of them
/// that hands out lines as string_views into a large buffer (no per-line
/// allocation) while tracking the uncompressed byte offset and the line number
/// of every line, so readers can index a file in one pass and seek back to any
/// line later. zlib stays out of every public header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace pdcg::atomistic::detail {

/// A readable, seekable stream of (uncompressed) bytes.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Reads up to n bytes; returns 0 at end of file.
  virtual std::size_t read(char* dst, std::size_t n) = 0;
  /// Moves to an uncompressed byte offset. For gzip: decompresses forward from
  /// the current position or from the last access point before the offset
  /// (access points are recorded every 4 MiB of output while reading forward).
  virtual void seek(std::uint64_t offset) = 0;
  virtual bool compressed() const = 0;

  /// Opens `path`; gzip is detected by its magic bytes (1f 8b), not the name.
  /// Throws InputError when the file cannot be opened.
  static std::unique_ptr<ByteSource> open(const std::string& path);
};

/// Buffered line reader. Lines are returned without the trailing '\n' (a
/// trailing '\r' is left in place; callers treat it as a blank).
///
/// The buffer starts at kInitialBytes and doubles, up to `chunk_bytes`, each time a buffer's
/// worth of the file has been read through it, so a small file costs one 64 KiB buffer
/// (opening one is cheap, e.g. thousands of small inputs in a fuzzing run) while a large file
/// is read in `chunk_bytes` pieces after a few refills. A line longer than the buffer doubles
/// it further, whatever its size.
class LineReader {
 public:
  static constexpr std::size_t kInitialBytes = std::size_t{64} << 10;
  explicit LineReader(ByteSource& source, std::size_t chunk_bytes = std::size_t{8} << 20);

  /// Next line, or false at end of file. The view stays valid until the next call.
  bool next(std::string_view& line);
  /// 1-based number of the line last returned by next().
  long line_number() const { return line_no_; }
  /// Uncompressed byte offset of the start of the line next() would return.
  std::uint64_t offset() const { return buf_offset_ + pos_; }
  /// Positions the reader so that next() returns the line starting at `offset`,
  /// which is line number `line_number` of the file.
  void seek(std::uint64_t offset, long line_number);

 private:
  bool refill();  // keeps [pos_, end_), reads more; false if nothing more
  ByteSource& src_;
  std::vector<char> buf_;
  std::size_t chunk_;  // the size the buffer grows to by refills (not a limit on line length)
  std::size_t pos_ = 0, end_ = 0;
  std::uint64_t buf_offset_ = 0;  // file offset of buf_[0]
  std::size_t streamed_ = 0;      // bytes read into the buffer since it last grew
  long line_no_ = 0;
  bool eof_ = false;
};

}  // namespace pdcg::atomistic::detail
