/// libFuzzer harness: EAM potential files (DYNAMO funcfl for pair_style eam, setfl for
/// eam/alloy, Finnis–Sinclair setfl for eam/fs), read, converted and splined as LAMMPS does
/// (build_eam_tables), then one family evaluated. First byte: bits 0-1 the style
/// (0 eam, 1 eam/alloy, 2 eam/fs, 3 eam/alloy), bit 2 units real instead of metal (the
/// metal→real conversion of tagged files), bit 3 two atom types instead of one. The rest is
/// the file; the setfl element names are taken from its fourth line.
#include <cctype>
#include <sstream>

#include "fuzz_common.hpp"
#include "fuzz_potential.hpp"
#include "pdcg/atomistic/potential_file.hpp"

namespace {

/// Up to `n` element names from line 4 of a setfl file ("Nelements El1 El2 ..."); names
/// that would not survive as one command word become "X".
std::vector<std::string> setfl_elements(std::string_view text, int n) {
  std::size_t pos = 0;
  for (int line = 0; line < 3 && pos != std::string_view::npos; ++line) {
    pos = text.find('\n', pos);
    if (pos != std::string_view::npos) ++pos;
  }
  std::vector<std::string> words;
  if (pos != std::string_view::npos) {
    const auto end = text.find('\n', pos);
    std::istringstream in(
        std::string(text.substr(pos, end == std::string_view::npos ? end : end - pos)));
    std::string w;
    in >> w;  // the element count
    while (in >> w && static_cast<int>(words.size()) < n) {
      bool ok = !w.empty() && w.size() < 16;
      for (char ch : w) ok = ok && std::isalnum(static_cast<unsigned char>(ch));
      words.push_back(ok ? w : "X");
    }
  }
  while (static_cast<int>(words.size()) < n) words.push_back(words.empty() ? "X" : words.back());
  return words;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("eam", ".eam");
  if (size == 0) return 0;
  static const char* styles[] = {"eam", "eam/alloy", "eam/fs", "eam/alloy"};
  const std::string style = styles[data[0] & 3];
  const std::string units = (data[0] & 4) ? "real" : "metal";
  const int ntypes = (data[0] & 8) ? 2 : 1;
  pdcg::fuzz::write_file(path, data + 1, size - 1);
  std::string deck = "units " + units + "\npair_style " + style + "\n";
  if (style == "eam") {
    deck += "pair_coeff * * " + path + "\n";
  } else {
    const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
    deck += "pair_coeff * * " + path;
    for (const auto& e : setfl_elements(text, ntypes)) deck += " " + e;
    deck += "\n";
  }
  return pdcg::fuzz::guarded([&] {
    auto spec = pdcg::atomistic::read_potential_commands_from_string(deck, "fuzz.in", ntypes);
    pdcg::fuzz::build_and_evaluate(spec);
  });
}
