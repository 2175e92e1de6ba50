/// libFuzzer harness: pdcg result and checkpoint HDF5 files as `pdcg info` and a restart
/// read them (H5Reader: the root's identification, then every group, dataset and the
/// attributes the readers ask for, two levels deep). HDF5 opens files by name: the input
/// is written to a scratch file.
#include <functional>

#include "fuzz_common.hpp"
#include "pdcg/io/hdf5.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("h5_result", ".h5");
  pdcg::fuzz::write_file(path, data, size);
  return pdcg::fuzz::guarded([&] {
    pdcg::io::H5Reader file(path);
    (void)file.info();
    for (const char* a : {"kind", "step", "t", "dimension", "points"})
      if (file.has_attribute("/", a)) {
        try {
          (void)file.attribute_string("/", a);
        } catch (const pdcg::Error&) {
          (void)file.attribute_double("/", a);
        }
      }
    std::function<void(const std::string&, int)> walk = [&](const std::string& group, int depth) {
      for (const auto& name : file.list(group)) {
        const std::string p = (group == "/" ? "" : group) + "/" + name;
        bool is_group = true;
        try {
          (void)file.list(p);
        } catch (const pdcg::Error&) {
          is_group = false;
        }
        if (is_group) {
          if (depth < 2) walk(p, depth + 1);
          continue;
        }
        (void)file.dims(p);
        // the reader must refuse a mismatched type with an InputError, never misread it
        for (int kind = 0; kind < 4; ++kind) try {
            if (kind == 0) (void)file.read_double(p);
            if (kind == 1) (void)file.read_int(p);
            if (kind == 2) (void)file.read_string(p);
            if (kind == 3) (void)file.read_strings(p);
          } catch (const pdcg::Error&) {
          }
      }
    };
    walk("/", 0);
  });
}
