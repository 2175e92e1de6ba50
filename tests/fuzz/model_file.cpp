/// libFuzzer harness: pdcg model files (HDF5 "pdcg-body", read_body with the default
/// potential factory: stored LAMMPS commands and embedded files rebuilt into a native
/// potential). HDF5 opens files by name: the input is written to a scratch file.
#include "pdcg/body/model_file.hpp"

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("model_file", ".h5");
  pdcg::fuzz::write_file(path, data, size);
  return pdcg::fuzz::guarded([&] { (void)pdcg::body::read_body(path); });
}
