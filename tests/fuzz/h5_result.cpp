/// libFuzzer harness: pdcg result and checkpoint HDF5 files as `pdcg info` and a restart
/// read them (H5Reader, h5_walk.hpp), from mutated file bytes. HDF5 opens files by name: the
/// input is written to a scratch file. Mutated bytes mostly exercise HDF5 1.10.8's own parser
/// (which crashes on some of them: tests/fuzz/run.sh replays this corpus only); h5_struct
/// fuzzes pdcg's validation of valid HDF5 files instead.
#include "fuzz_common.hpp"
#include "h5_walk.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("h5_result", ".h5");
  pdcg::fuzz::write_file(path, data, size);
  return pdcg::fuzz::guarded([&] {
    pdcg::io::H5Reader file(path);
    pdcg::fuzz::walk_h5(file);
  });
}
