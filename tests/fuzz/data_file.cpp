/// libFuzzer harness: LAMMPS data files (read_data, atom style from the header comment or
/// guessed; first byte picks an explicit style hint) and read_atoms' file-kind detection.
#include "pdcg/atomistic/data_file.hpp"

#include "fuzz_common.hpp"
#include "pdcg/atomistic/dump_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using pdcg::atomistic::AtomStyle;
  static const std::string path = pdcg::fuzz::scratch_path("data_file", ".data");
  if (size == 0) return 0;
  static const AtomStyle hints[] = {AtomStyle::unknown, AtomStyle::atomic, AtomStyle::charge,
                                    AtomStyle::bond,    AtomStyle::angle,  AtomStyle::molecular,
                                    AtomStyle::full,    AtomStyle::unknown};
  const AtomStyle hint = hints[data[0] & 7];
  pdcg::fuzz::write_file(path, data + 1, size - 1);
  return pdcg::fuzz::guarded([&] {
    if (pdcg::atomistic::detect_atom_file_kind(path) != pdcg::atomistic::AtomFileKind::data) return;
    (void)pdcg::atomistic::read_data(path, hint);
  });
}
