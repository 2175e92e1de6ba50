/// \file
/// HDF5 files of pdcg (schema in docs/formats.md).
///
/// Every file written by H5Writer carries, as attributes of the root group:
///   format          e.g. "pdcg-body", "pdcg-results"
///   schema_version  integer, incremented on incompatible changes
///   pdcg_version    the writing program's version
///   units           LAMMPS unit style of every quantity in the file
///   command_line    the command that produced the file
/// Every dataset carries an attribute `crc32` (CRC-32 of its values in native byte order, or
/// of its strings with their NULs); H5Reader verifies it on every read and verify() checks
/// all datasets: a damaged file is an InputError naming file and dataset, never silent data.
/// Writes go to a temporary file beside the final one; commit() renames it
/// into place (see atomic_output.hpp); a full disk is pdcg::Error naming the final file, the
/// OS error and the fix. HDF5 headers stay out of this header.
///
/// In memory (InMemory): the same writer and reader on a file that never touches the disk
/// (HDF5's core driver without a backing store, and file images). For tests and the fuzz
/// harnesses, which write and read a whole file per input; pdcg's own output always goes
/// through a file (temporary + rename).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pdcg/core/units.hpp"

namespace pdcg::io {

/// Identification written into the root of every file.
struct FileInfo {
  std::string format;      ///< e.g. "pdcg-body"
  int schema_version = 1;  ///< of that format
  UnitStyle units = UnitStyle::none;
  std::string pdcg_version;  ///< filled by the writer if empty
  std::string command_line;  ///< filled from pdcg::command_line() if empty
};

/// The bytes of a complete HDF5 file held in memory (an HDF5 "file image").
using H5Image = std::vector<unsigned char>;

/// Selects the in-memory constructors of H5Writer and H5Reader; `name` stands for the file
/// in error messages (it is not a path: nothing is created or opened under it).
struct InMemory {
  std::string name;
};

/// Writes one HDF5 file atomically. Paths like "families/offsets" create
/// intermediate groups. Arrays are row-major; `dims` defaults to {size}.
class H5Writer {
 public:
  H5Writer(std::filesystem::path final_path, FileInfo info);
  /// A file in memory only: commit() closes it and image() returns its bytes.
  H5Writer(InMemory file, FileInfo info);
  ~H5Writer();  ///< without commit(): closes and deletes the temporary
  H5Writer(const H5Writer&) = delete;
  H5Writer& operator=(const H5Writer&) = delete;

  void write(std::string_view path, std::span<const double> data,
             std::vector<std::size_t> dims = {});
  void write(std::string_view path, std::span<const std::int64_t> data,
             std::vector<std::size_t> dims = {});
  void write(std::string_view path, std::string_view text);  ///< scalar string dataset
  void write_strings(std::string_view path, const std::vector<std::string>& lines);

  void attribute(std::string_view object, std::string_view name, double value);
  void attribute(std::string_view object, std::string_view name, std::int64_t value);
  void attribute(std::string_view object, std::string_view name, std::string_view value);

  /// Flushes, closes and renames into place. Nothing is visible under the
  /// final name before this returns. In memory: flushes and closes; image() holds the file.
  void commit();
  /// The complete file of an in-memory writer after commit(); std::logic_error for a writer
  /// to disk or before commit().
  const H5Image& image() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a pdcg HDF5 file. Opening checks that it is HDF5 and carries a
/// pdcg `format` attribute; errors name the file and the missing item.
class H5Reader {
 public:
  explicit H5Reader(std::filesystem::path path);
  /// Reads a file image (e.g. H5Writer::image(); the bytes are copied). Checks as on disk;
  /// errors name `file.name`, which path() returns.
  H5Reader(InMemory file, std::span<const unsigned char> image);
  ~H5Reader();
  H5Reader(const H5Reader&) = delete;
  H5Reader& operator=(const H5Reader&) = delete;

  const FileInfo& info() const;
  /// Throws InputError unless info().format == format and the schema version is known.
  void require_format(std::string_view format, int max_schema_version) const;

  bool exists(std::string_view path) const;
  std::vector<std::size_t> dims(std::string_view path) const;
  std::vector<double> read_double(std::string_view path) const;
  std::vector<std::int64_t> read_int(std::string_view path) const;
  std::string read_string(std::string_view path) const;
  std::vector<std::string> read_strings(std::string_view path) const;
  /// Reads every dataset and checks its crc32 attribute (where present): InputError
  /// naming the dataset on a mismatch or an unreadable (truncated) file.
  void verify() const;
  /// Names of the members of a group.
  std::vector<std::string> list(std::string_view group = "/") const;

  bool has_attribute(std::string_view object, std::string_view name) const;
  double attribute_double(std::string_view object, std::string_view name) const;
  std::int64_t attribute_int(std::string_view object, std::string_view name) const;
  std::string attribute_string(std::string_view object, std::string_view name) const;

  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// HDF5 library version, e.g. "1.10.8".
std::string hdf5_version();

}  // namespace pdcg::io
