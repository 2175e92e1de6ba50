/// \file
/// Atomic output files: write to a temporary file in the destination
/// directory, rename it into place on commit(). A run that is interrupted
/// (exception, signal, SIGKILL, full disk) never leaves a half-written file under
/// the final name, and an older file under that name stays intact until the rename.
///
/// Temporaries are named ".<name>.tmp.<pid>.<n>" (hidden, beside the final file).
/// An exception removes its temporary; a killed process leaves it behind, and
/// remove_stale_temporaries() (called by `pdcg run` on its output directory)
/// deletes those of processes that no longer exist.
///
/// Write errors (ENOSPC, EFBIG under `ulimit -f`, EDQUOT, EIO, ...) throw
/// pdcg::Error naming the final file, the OS error and the fix. commit() fsyncs
/// the file before the rename and the directory after it, so a file under its
/// final name is complete also after a power loss.
#pragma once

#include <filesystem>
#include <memory>
#include <ostream>
#include <string_view>

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
  /// fsyncs the temporary, renames it to the final path (atomic on POSIX), fsyncs the
  /// directory. Throws pdcg::Error (write_error) on failure; the temporary is then removed.
  void commit();
  bool committed() const { return committed_; }

 private:
  std::filesystem::path final_, temporary_;
  bool committed_ = false;
};

/// A text or binary file (CSV, JSON, YAML, PNG) written atomically.
/// \code
///   AtomicTextFile out("forces.csv");
///   out.stream() << "id,fx,fy,fz\n";
///   out.commit();
/// \endcode
class AtomicTextFile {
 public:
  explicit AtomicTextFile(std::filesystem::path final_path);
  ~AtomicTextFile();
  AtomicTextFile(AtomicTextFile&&) noexcept;
  AtomicTextFile& operator=(AtomicTextFile&&) = delete;
  /// Output stream on the temporary. A failed write sets badbit; commit() reports it.
  std::ostream& stream();
  /// Flushes, checks every write, fsyncs, closes, renames. Throws pdcg::Error on I/O
  /// failure (the final file is then untouched and the temporary removed).
  void commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Throws pdcg::Error: "cannot write FILE: <strerror(err)> (errno N) while <during>" and a
/// fix that fits the error (full disk / file size limit / read-only / permissions).
[[noreturn]] void throw_write_error(const std::filesystem::path& final_path, int err,
                                    std::string_view during);

/// Before any computation: checks that `file` can be created — its directory exists or is
/// created, and a probe file can be created and removed there. Throws InputError naming the
/// file, the OS error and the fix (`option` names the command-line option, e.g. "--output").
void require_writable_output(const std::filesystem::path& file, std::string_view option = {});
/// Same for an output directory (created when missing).
void require_writable_directory(const std::filesystem::path& dir, std::string_view option = {});

/// Deletes temporaries (".<name>.tmp.<pid>.<n>") in dir whose process no longer exists
/// (left by a killed run). Returns the number removed.
int remove_stale_temporaries(const std::filesystem::path& dir);

}  // namespace pdcg::io
