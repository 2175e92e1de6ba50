/// \file
/// Effects of a scene (`effects: [...]`, docs/effects.md) and their registry.
///
/// An effect is a Component (its sections, numeric keys, parsing, resolved output) with a name
/// (the word listed in `effects:`) and a run part: attach() gives the run an EffectRun with the
/// per-step hook, the CSV columns and result fields it writes, and its checkpoint/restore.
/// Register one with a line at namespace scope of a source file linked into the executable:
/// \code
///   PDCG_REGISTER_EFFECT(strain_probe, MyEffect)
/// \endcode
/// (tests/unit/scene/test_registries.cpp does it). The built-in effects (inertia, damping,
/// rupture) are registered by an explicit list in the scene library, so that a static link
/// cannot drop them; their run part is the runners' own code (src/scene/run_*.cpp).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/scene/component.hpp"

namespace pdcg::io {
class H5Writer;
class H5Reader;
}  // namespace pdcg::io

namespace pdcg::solver {
class Discretization;
class Model;
class Material;
struct DisplacementSet;
}  // namespace pdcg::solver

namespace pdcg::scene {

/// What an effect sees of a run.
struct RunContext {
  const Scene& scene;
  const std::filesystem::path& directory;
  const solver::Discretization& body;
  const solver::Model& model;
  const solver::Material& material;
  const std::vector<solver::DisplacementSet>& displacement_sets;
  bool dynamic;  ///< explicit dynamics (inertia) or quasi-static load steps
};

/// The state after a (load or time) step.
struct StepState {
  long step;                 ///< load step (0 = the start) or time step
  double t;                  ///< load factor or time
  const Eigen::VectorXd& u;  ///< displacements, d per point
  const Eigen::VectorXd* v;  ///< velocities (dynamic runs), else null
};

/// The run part of an effect, created by Effect::attach before the first step.
class EffectRun {
 public:
  virtual ~EffectRun() = default;
  /// Columns it appends to reactions.csv / series.csv (after the built-in ones).
  virtual std::vector<std::string> columns() const { return {}; }
  /// After every sampled step (each row of the CSV): one value per column.
  virtual void on_step(const StepState& state, std::vector<double>& values) {
    (void)state;
    (void)values;
  }
  /// Fields it adds to results_NNNN.h5 (e.g. "fields/my_field").
  virtual void write_fields(io::H5Writer& h5, const StepState& state) const {
    (void)h5;
    (void)state;
  }
  /// Its state into a checkpoint (under "effects/<name>/"), and back on --restart.
  virtual void checkpoint(io::H5Writer& h5, const std::string& group) const {
    (void)h5;
    (void)group;
  }
  virtual void restore(const io::H5Reader& h5, const std::string& group) {
    (void)h5;
    (void)group;
  }
};

class Effect : public Component {
 public:
  /// Its section: the effect's name, parsed and written after the built-in effects.
  std::vector<Section> sections() const override { return {{name(), 700, 700}}; }
  /// The word listed in `effects:` (set by the registry).
  const std::string& name() const { return name_; }
  /// Checks made whether or not the scene lists the effect, after the list is read and before
  /// any effect section is parsed (e.g. damping without inertia).
  virtual void check_listing(const Reader& r, const Node& root, const Scene& s) const {
    (void)r;
    (void)root;
    (void)s;
  }
  /// Its run part; null when it has none (the built-in effects run in the runners' code).
  virtual std::unique_ptr<EffectRun> attach(const RunContext& run) const {
    (void)run;
    return nullptr;
  }
  /// Listed in the scene's `effects:`.
  bool listed(const Scene& s) const;
  void set_name(std::string n) { name_ = std::move(n); }

 private:
  std::string name_;
};

using EffectFactory = std::function<std::unique_ptr<Effect>()>;

/// Adds an effect to the registry (names are unique; InputError-free: a duplicate is a
/// programming error and throws pdcg::Error). Returns true, for static registration.
bool register_effect(const std::string& name, EffectFactory factory);
/// The registered effect names, built-in first (inertia, damping, rupture), then in order of
/// registration.
std::vector<std::string> registered_effects();
/// A fresh instance of a registered effect (null if unknown).
std::unique_ptr<Effect> make_effect(const std::string& name);

}  // namespace pdcg::scene

/// Registers effect `Type` (default-constructible, derived from pdcg::scene::Effect) as `name`
/// (an identifier: the word of `effects: [name]` and the section `name:`).
#define PDCG_REGISTER_EFFECT(name, Type)                                          \
  namespace {                                                                     \
  const bool PDCG_SCENE_CONCAT(pdcg_effect_registered_,                           \
                               name) = ::pdcg::scene::register_effect(#name, [] { \
    return std::make_unique<Type>();                                              \
  });                                                                             \
  }
