/// libFuzzer harness: gzip-compressed LAMMPS dumps (the gzip random-access source under
/// DumpReader). First byte odd: the rest is written as is (corrupt, truncated or
/// concatenated gzip streams); even: the rest is a dump text that the harness gzips, so
/// that mutations of the text still reach the reader through a valid stream.
#include <zlib.h>

#include "fuzz_common.hpp"
#include "pdcg/atomistic/dump_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("dump_gzip", ".dump.gz");
  if (size == 0) return 0;
  const bool raw = data[0] & 1;
  ++data;
  --size;
  if (raw) {
    pdcg::fuzz::write_file(path, data, size);
  } else {
    gzFile gz = gzopen(path.c_str(), "wb1");
    if (!gz) std::abort();
    if (size && gzwrite(gz, data, static_cast<unsigned>(size)) != static_cast<int>(size))
      std::abort();
    if (gzclose(gz) != Z_OK) std::abort();
  }
  return pdcg::fuzz::guarded([&] {
    pdcg::atomistic::DumpReader dump(path);
    // frames in reverse: random access goes back through the gzip checkpoints
    for (std::size_t n = dump.nframes(); n-- > 0;) (void)dump.frame(n);
    if (dump.nframes() > 0) (void)dump.frame(0);
  });
}
