/// \file
/// HDF5 model files of PD bodies (format "pdcg-body", schema in docs/formats.md): kind, units,
/// dimension, points, masses, families (CSR), the potential as its LAMMPS command lines plus
/// the contents of every file they name (self-contained), statistics, homogenisation layer
/// (kernel, points, weights), ε, provenance.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "pdcg/body/body.hpp"

namespace pdcg::io {
class H5Reader;
}

namespace pdcg::body {

inline constexpr int kBodySchemaVersion = 1;

/// Writes the body atomically (temporary file renamed into place).
void write_body(const Body& body, const std::filesystem::path& path);

/// Rebuilds the potential of a stored body from its command lines and embedded files.
using PotentialFactory = std::function<std::shared_ptr<const atomistic::Potential>(
    const atomistic::PotentialSpec& spec, const std::vector<EmbeddedFile>& files)>;

/// The contents of every file the potential's pair_coeff lines name (EAM tables …), read
/// where LAMMPS would find them; InputError naming the line when one is missing.
std::vector<EmbeddedFile> embed_potential_files(const atomistic::PotentialSpec& spec);

/// Rebuilds a native potential from stored command lines: embedded files are written to a
/// private temporary directory, the pair_coeff lines are pointed at them, the lines re-parsed
/// (read_potential_commands_from_string) and make_potential called. The default factory.
std::shared_ptr<const atomistic::Potential> potential_from_commands(
    const atomistic::PotentialSpec& stored, const std::vector<EmbeddedFile>& files);

/// The factory read_body uses when none is given (set by the module that knows how to make
/// potentials from LAMMPS commands): potential_from_commands unless replaced.
PotentialFactory& default_potential_factory();

/// Reads a body. The potential is rebuilt by `factory` (or the default factory) and wrapped
/// for ε ≠ 1; without any factory the body has no potential (Evaluator then refuses it).
/// Throws InputError naming the file and the missing or inconsistent item.
Body read_body(const std::filesystem::path& path, const PotentialFactory& factory = {});
/// The same from an open file (e.g. one in memory, io::InMemory); errors name file.path().
Body read_body(const io::H5Reader& file, const PotentialFactory& factory = {});

}  // namespace pdcg::body
