/// libFuzzer harness: LAMMPS commands files and input decks (units, boundary, atom_style,
/// mass, pair_style/pair_coeff/pair_modify, bond_style/bond_coeff, special_bonds, and the
/// lines a deck carries besides them). First byte: the configuration's number of atom types,
/// 1-4 (pdcg always reads commands with the type count of a configuration: atoms2pd from the
/// data file or dump, a model file from its stored count). Accepted specs of the closed-form native
/// styles (lj/cut, morse, zero, bonds only) are built into potentials; file-based styles have their
/// own harnesses (eam, manybody) and LAMMPS styles are not run.
#include "fuzz_common.hpp"
#include "fuzz_potential.hpp"
#include "pdcg/atomistic/potential_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int ntypes = 1 + data[0] % 4;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  return pdcg::fuzz::guarded([&] {
    auto spec = pdcg::atomistic::read_potential_commands_from_string(text, "fuzz.in", ntypes);
    pdcg::atomistic::require_supported_styles(spec, false);
    const auto& ps = spec.pair_style;
    if (ps == "lj/cut" || ps == "morse" || ps == "zero" || (ps.empty() && !spec.bond_style.empty()))
      pdcg::fuzz::build_and_evaluate(spec);
  });
}
