/// libFuzzer harness: pdcg model files (HDF5 "pdcg-body", read_body with the default
/// potential factory: stored LAMMPS commands and embedded files rebuilt into a native
/// potential). HDF5 opens files by name: the input is written to a scratch file.
#include "pdcg/body/model_file.hpp"

#include "fuzz_common.hpp"
#include "fuzz_potential.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("model_file", ".h5");
  pdcg::fuzz::write_file(path, data, size);
  // the default factory, except that a non-native style is refused here (fuzz_potential.hpp)
  const pdcg::body::PotentialFactory native_only =
      [](const pdcg::atomistic::PotentialSpec& spec,
         const std::vector<pdcg::body::EmbeddedFile>& files)
      -> std::shared_ptr<const pdcg::atomistic::Potential> {
    if (!pdcg::fuzz::native_style(spec.pair_style))
      throw pdcg::InputError("non-native pair style (not fuzzed)").value(spec.pair_style);
    return pdcg::body::potential_from_commands(spec, files);
  };
  return pdcg::fuzz::guarded([&] { (void)pdcg::body::read_body(path, native_only); });
}
