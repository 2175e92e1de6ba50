/// \file
/// Atomic output files: write to a temporary file in the destination
/// directory, rename it into place on commit(). A run that is interrupted
/// (exception, signal, crash) never leaves a half-written file under the final
/// name, and an older file under that name stays intact until the rename.
#pragma once

#include <filesystem>
#include <fstream>

namespace pdcg::io {

/// Temporary-name management shared by all writers.
class AtomicPath {
 public:
  explicit AtomicPath(std::filesystem::path final_path);
  ~AtomicPath();  ///< removes the temporary if commit() was not reached
  AtomicPath(const AtomicPath&) = delete;
  AtomicPath& operator=(const AtomicPath&) = delete;

  const std::filesystem::path& temporary() const { return temporary_; }
  const std::filesystem::path& final_path() const { return final_; }
  /// Renames the temporary to the final path (atomic on POSIX).
  void commit();
  bool committed() const { return committed_; }

 private:
  std::filesystem::path final_, temporary_;
  bool committed_ = false;
};

/// A text file (CSV, JSON, YAML) written atomically.
/// \code
///   AtomicTextFile out("forces.csv");
///   out.stream() << "id,fx,fy,fz\n";
///   out.commit();
/// \endcode
class AtomicTextFile {
 public:
  explicit AtomicTextFile(std::filesystem::path final_path);
  std::ofstream& stream() { return stream_; }
  /// Flushes, checks the stream, closes, renames. Throws pdcg::Error on I/O failure.
  void commit();

 private:
  AtomicPath path_;
  std::ofstream stream_;
};

}  // namespace pdcg::io
