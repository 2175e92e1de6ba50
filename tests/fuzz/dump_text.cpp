/// libFuzzer harness: LAMMPS text dumps (DumpReader: index every frame, read each).
#include "fuzz_common.hpp"
#include "pdcg/atomistic/dump_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("dump_text", ".dump");
  pdcg::fuzz::write_file(path, data, size);
  return pdcg::fuzz::guarded([&] {
    pdcg::atomistic::DumpReader dump(path);
    (void)dump.units();
    (void)dump.column_sets();
    for (std::size_t n = 0; n < dump.nframes(); ++n) {
      (void)dump.info(n);
      (void)dump.columns(n);
      (void)dump.frame(n);
    }
  });
}
