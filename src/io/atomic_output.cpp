#include "pdcg/io/atomic_output.hpp"

#include <unistd.h>

#include <atomic>
#include <string>
#include <system_error>

#include "pdcg/core/error.hpp"

namespace pdcg::io {

namespace {
std::atomic<unsigned> g_counter{0};
}

AtomicPath::AtomicPath(std::filesystem::path final_path) : final_(std::move(final_path)) {
  if (final_.filename().empty())
    throw InputError("output path names a directory, not a file")
        .value(final_.string())
        .expected("a file name")
        .fix("add a file name, e.g. out/result.h5");
  const auto dir = final_.parent_path();
  if (!dir.empty() && !std::filesystem::is_directory(dir)) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec)
      throw InputError("cannot create output directory")
          .value(dir.string())
          .expected("a writable directory")
          .fix(ec.message());
  }
  // ".<name>.tmp.<pid>.<n>": hidden, unique per process and writer.
  std::string name = ".";
  name.append(final_.filename().string());
  name.append(".tmp.");
  name.append(std::to_string(getpid()));
  name.push_back('.');
  name.append(std::to_string(g_counter++));
  temporary_ = dir / name;
}

AtomicPath::~AtomicPath() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temporary_, ec);
  }
}

void AtomicPath::commit() {
  std::error_code ec;
  std::filesystem::rename(temporary_, final_, ec);
  if (ec)
    throw Error("cannot move " + temporary_.string() + " to " + final_.string() + ": " +
                ec.message());
  committed_ = true;
}

AtomicTextFile::AtomicTextFile(std::filesystem::path final_path) : path_(std::move(final_path)) {
  stream_.open(path_.temporary());
  if (!stream_)
    throw InputError("cannot open output file for writing")
        .value(path_.final_path().string())
        .expected("a writable location")
        .fix("check the directory exists and is writable");
  stream_.precision(17);
}

void AtomicTextFile::commit() {
  stream_.flush();
  if (!stream_) throw Error("write error on " + path_.temporary().string());
  stream_.close();
  path_.commit();
}

}  // namespace pdcg::io
