/// \file
/// The files of a run: results_NNNN.h5 and results.xdmf, checkpoints (write and restart), and
/// small helpers shared by the runners. Private to the scene module.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg/scene/scene.hpp"

namespace pdcg::scene {

void write_xdmf(const std::filesystem::path& dir, std::size_t n,
                const std::vector<std::pair<int, double>>& steps, bool damage,
                bool velocity = false);

/// results_NNNN.h5: points and fields at displacement u (and velocity v when given).
void write_fields(const std::filesystem::path& dir, const Scene& s,
                  const solver::Discretization& body, const solver::Model& model,
                  const solver::Material& material, const Eigen::VectorXd& u,
                  const Eigen::VectorXd* v, bool damage, int step,
                  const std::function<void(io::H5Writer&)>& attributes);

struct Restart {
  std::filesystem::path file;
  std::string kind;  // static | dynamic
  long step = 0;     // completed (load or time) steps
  double t = 0.0;
  std::string series;
  std::vector<std::pair<int, double>> written;
  std::unique_ptr<io::H5Reader> h5;
  std::vector<double> vec(const char* name) const { return h5->read_double(name); }
};

/// The last checkpoint of dir, checked (checksums, format, the same scene).
Restart load_checkpoint(const Scene& s, const std::filesystem::path& dir);

/// Starts a checkpoint file with the common part; the caller adds the state and commits.
std::unique_ptr<io::H5Writer> begin_checkpoint(const Scene& s, const std::filesystem::path& dir,
                                               const char* kind, long step, double t,
                                               const std::string& series,
                                               const std::vector<std::pair<int, double>>& written);

/// Commits h5 and deletes the older checkpoints of dir.
void finish_checkpoint(io::H5Writer& h5, const std::filesystem::path& dir, long step);

/// An InputError of the solver set-up as an error of the scene file (file:line of its key).
InputError& with_line(const Scene& s, InputError& e);

/// The run parts of the scene's listed effects that have one, with their names.
using EffectRuns = std::vector<std::pair<std::string, std::unique_ptr<EffectRun>>>;
EffectRuns attach_effects(const Scene& s, const RunContext& context);
/// ",v1,v2,…" of every column of the runs after a step (values in format `fmt`).
std::string effect_values(const EffectRuns& runs, const StepState& state, const char* fmt);

Eigen::VectorXd vec_of(const std::vector<double>& v);
std::vector<double> std_of(const Eigen::VectorXd& v);

/// The explicit-dynamics run (effects: [inertia]).
void run_dynamic(const Scene& s, const std::filesystem::path& dir,
                 const std::optional<Restart>& restart, solver::Discretization& body,
                 solver::Model& model, const solver::Material& material,
                 std::vector<solver::DisplacementSet> dsets, std::vector<solver::TractionSet> tsets,
                 const std::function<void()>& begin_outputs, const RunOptions& run_options);

}  // namespace pdcg::scene
