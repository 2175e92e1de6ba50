/// libFuzzer harness: Stillinger-Weber and Tersoff parameter files (pair_style sw/tersoff,
/// read_triple_table and the per-style checks), then one family evaluated. First byte:
/// bit 0 the style (0 sw, 1 tersoff), bit 1 two atom types mapped to the first two elements
/// of the file instead of one, bit 2 units real (the metal→real conversion). The rest is the
/// file; element names are the first words of its first two entries.
#include <cctype>
#include <sstream>

#include "fuzz_common.hpp"
#include "fuzz_potential.hpp"
#include "pdcg/atomistic/potential_file.hpp"

namespace {

/// The first word of the first `n` distinct non-comment lines ("X" when unusable).
std::vector<std::string> first_elements(std::string_view text, int n) {
  std::vector<std::string> out;
  std::istringstream in{std::string(text)};
  std::string line;
  while (static_cast<int>(out.size()) < n && std::getline(in, line)) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string w;
    if (!(words >> w)) continue;
    bool ok = w.size() < 16;
    for (char ch : w) ok = ok && std::isalnum(static_cast<unsigned char>(ch));
    if (!ok) w = "X";
    if (out.empty() || out.back() != w) out.push_back(w);
  }
  while (static_cast<int>(out.size()) < n) out.push_back(out.empty() ? "X" : out.back());
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("manybody", ".pot");
  if (size == 0) return 0;
  const std::string style = (data[0] & 1) ? "tersoff" : "sw";
  const int ntypes = (data[0] & 2) ? 2 : 1;
  const std::string units = (data[0] & 4) ? "real" : "metal";
  pdcg::fuzz::write_file(path, data + 1, size - 1);
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  std::string deck = "units " + units + "\npair_style " + style + "\npair_coeff * * " + path;
  for (const auto& e : first_elements(text, ntypes)) deck += " " + e;
  deck += "\n";
  return pdcg::fuzz::guarded([&] {
    auto spec = pdcg::atomistic::read_potential_commands_from_string(deck, "fuzz.in", ntypes);
    pdcg::fuzz::build_and_evaluate(spec);
  });
}
