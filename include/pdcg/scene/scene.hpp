/// \file
/// Static scenes for the BA correspondence solver (`pdcg run scene.yaml`).
///
/// Scene contract:
/// \code{.yaml}
///   units: none            # lj | metal | real | si | none
///   dimension: 2
///   plane: strain          # strain | stress (2D only)
///   geometry: {shape: rectangle, origin: [0, 0], size: [1, 1], spacing: 0.025,
///              holes: [{center: [0.5, 0.5], radius: 0.2}], cracks: [{from: [0, 0.5], to: [0.2,
///              0.5]}]}
///   horizon: {factor: 3.015}            # or {value: 0.075}
///   material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
///   # or the Cauchy–Born material of a pdcg model file (docs/elastic.md §6):
///   # material: {model: cauchy-born, file: res.h5}   # path relative to the scene file
///   # the points of a model file as the body (docs/solver.md §2.1), and a per-point material
///   # (docs/elastic.md §7):
///   # geometry: {shape: model, file: res.h5}
///   # material: {model: cauchy-born, file: res.h5, per_point: true}
///   boundary:
///     - {name: left,  region: {x_max: 0.0},  displacement: {x: 0.0}}
///     - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}
///     - {name: right, region: {x_min: 1.0},  displacement: {x: "0.5*t"}}
///     - {name: top,   region: {y_min: 1.0},  traction: [0.0, 0.0]}
///   loading: {steps: 20}
///   solver: {type: newton, tolerance: 1.0e-8, max_iterations: 30, linear: cholmod}
///   output: {directory: out, every: 1}
/// \endcode
/// Extensions: solver.formulation (weak | energy), solver.correspondence
/// (bond-associated | classical), solver.max_cutbacks, solver.check_stability (bool,
/// default false: LDLᵀ inertia of the converged tangent after every load step, NumericalError
/// on a negative eigenvalue; one extra factorisation per step), solver.matrix_free (bool,
/// default false, needs linear: gmres: tangent products from the per-stencil tangents, no
/// assembled K; docs/solver.md §4). Regions select points by
/// inclusive bounds with a tolerance of half a spacing, or the nearest `point`.
/// Displacement and traction values are numbers (constant) or expressions in t.
/// Unknown keys are errors listing the valid ones. Every numeric key is checked for type, sign,
/// range and finiteness (the rules each component declares, component.hpp), contradictions
/// between keys and with the body are refused, all before the output directory is created
/// (docs/solver.md §6). Each root section is read by a component (docs/architecture.md, "Scene
/// components"); materials and effects come from registries (material_model.hpp, effect.hpp).
/// Effects (docs/effects.md):
/// \code{.yaml}
///   effects: [rupture]
///   rupture: {criterion: bond_stretch, critical: 2.5}   # | principal_stretch | energy_density
///   rupture: {criterion: fracture_energy, G_c: 0.01}    # or surface_energy: γ (G_c = 2γ)
///   inertia: {integrator: velocity-verlet, time_step: auto, safety: 0.8, end_time: 10.0}
///   damping: {type: viscous, coefficient: 0.1}   # or {type: adaptive-dynamic-relaxation}
///   initial: {velocity: {x: "0.01*sin(pi*x)"}}  # expressions in x, y, z
///   output: {checkpoint_every: 100}               # restart: pdcg run scene.yaml --restart DIR
/// \endcode
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pdcg/core/units.hpp"
#include "pdcg/scene/effect.hpp"
#include "pdcg/scene/material_model.hpp"
#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/explicit.hpp"
#include "pdcg/solver/material.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg/solver/newton.hpp"
#include "pdcg/solver/point_cloud.hpp"
#include "pdcg/solver/rupture.hpp"

namespace pdcg::scene {

struct Region {
  std::array<std::optional<double>, 3> min, max;
  std::optional<solver::Vec3> point;
};

struct BoundaryCondition {
  std::string name;
  Region region;
  bool is_traction = false;
  std::array<std::string, 3> value_text;  ///< per component; empty = not given
  std::array<std::function<double(double)>, 3> value;
  /// `grip: surface` (displacement sets on a cell-centred grid): the prescribed values act on
  /// the body's face next to the selected points, through the PDDO extrapolation
  /// u_k + (F̄_k − I) o_k = ū with o_k = (Δx/2) n (docs/solver.md §4, "Grips on the
  /// surface"); `grip: points` (default) prescribes the points themselves.
  bool grip_surface = false;
};

/// `geometry: {shape: model, file: res.h5}`: the points of a pdcg model file (docs/solver.md
/// §2.1): homogenised models give their continuum points and volumes V_p; delta and rescaled
/// models their atoms (volumes: the lattice cell |det A| when the atoms form a lattice, else
/// V₀/N). The surface vectors s_k and the spacing come from solver::analyse_cloud.
struct ModelGeometry {
  std::filesystem::path file;
  std::string kind;  ///< body kind of the model (delta, homogenised, rescaled)
  std::vector<solver::Vec3> points;
  solver::CloudGeometry cloud;
};

struct Scene {
  std::filesystem::path source;
  /// Line (1-based) of every key of the scene file ("boundary[right].region.x_min"), so that
  /// errors found after parsing (regions, solver set-up) still name file:line.
  std::map<std::string, long> key_lines;
  UnitStyle units = UnitStyle::none;
  int dimension = 2;
  std::string plane = "strain";
  solver::GridSpec geometry;
  /// Set for `geometry.shape: model` (then `geometry` above is unused).
  std::shared_ptr<const ModelGeometry> model_geometry;
  /// The spacing of the body (grid spacing, or the model cloud's).
  double spacing() const {
    return model_geometry ? model_geometry->cloud.spacing : geometry.spacing;
  }
  double horizon_factor = 3.015, horizon_value = 0.0;
  double shear_modulus = 1.0, bulk_modulus = 10.0, density = 1.0;
  /// `material.model`: "neo-hookean" or "cauchy-born" (then `material_file` is the pdcg-body
  /// file, resolved against the scene file's directory, and density defaults to Σ M_k / V₀).
  std::string material_model = "neo-hookean";
  std::filesystem::path material_file;
  /// `material.per_point: true`: point p uses W_p of the model (body::PerPointCauchyBornMaterial);
  /// needs geometry.shape: model on the same file.
  bool material_per_point = false;
  /// `material.ion_relaxation` of the body-level Cauchy–Born material (docs/elastic.md §6):
  /// "automatic" (default: relaxed for a perfect crystal, clamped-ion with a warning
  /// otherwise), "relaxed" (a body that is not a perfect crystal is refused) or "clamped".
  std::string material_ion_relaxation = "automatic";
  /// The model of `material.model` with its own parameters (material_model.hpp); null for a
  /// Scene built in code (make_material then takes a fresh model of material_model).
  std::shared_ptr<const MaterialModel> material_impl;
  std::vector<BoundaryCondition> boundary;
  int steps = 20;
  solver::NewtonOptions newton;
  std::string linear_name = "umfpack";
  solver::ModelOptions model;
  std::filesystem::path output_directory = "out";
  int output_every = 1;
  /// `effects:` (docs/effects.md). Only what is listed is computed, allocated and written.
  std::vector<std::string> effects;
  /// The listed effects with their parameters (effect.hpp), in the registry's order; the
  /// built-in ones also fill the fields below.
  std::vector<std::shared_ptr<const Effect>> effect_objects;
  bool rupture = false;
  solver::RuptureOptions rupture_options;
  /// `inertia:` (explicit dynamics); without it the run is quasi-static (Newton).
  bool inertia = false;
  std::string integrator = "velocity-verlet";
  double time_step = 0.0;  ///< 0 = auto (safety × stable limit)
  double safety = 0.8;
  double end_time = 0.0;
  bool allow_unstable = false;
  /// `damping:` (with inertia): viscous (coefficient) or adaptive dynamic relaxation.
  std::string damping_type;  ///< empty = none
  double damping_coefficient = 0.0;
  /// `initial: {velocity: {x: …}}`: per component, expressions in x, y, z.
  std::array<std::string, 3> initial_velocity_text;
  std::array<std::function<double(const double*)>, 3> initial_velocity;
  /// Time series sample interval (steps) of dynamic runs.
  int series_every = 1;
  /// Checkpoint every N (load or time) steps; 0 = none.
  int checkpoint_every = 0;
};

/// Options of a run beyond the scene file.
struct RunOptions {
  std::optional<std::filesystem::path> output;   ///< replaces output.directory
  std::optional<std::filesystem::path> restart;  ///< continue from the last checkpoint there
  /// Distributed quasi-static run (pdcg::parallel, docs/scale-out.md): called once with the
  /// model and the PETSc solver; partitions the points, restricts the model's evaluation to
  /// this process's stencils and returns the StaticSolver's Distribution. Empty: serial.
  std::function<std::shared_ptr<solver::Distribution>(solver::Model&, solver::LinearSolver)>
      distribute = {};
  /// Distributed explicit dynamics (docs/scale-out.md §6): called once with the whole model;
  /// returns the ExplicitSolver's force exchange (this process's stencils, summed over the
  /// processes). Empty: serial.
  std::function<std::unique_ptr<solver::ForceExchange>(const solver::Model&)> distribute_explicit =
      {};
  int processes = 1;  ///< MPI processes of the run
  int rank = 0;       ///< this process (only rank 0 writes the outputs)
};

/// Effects a scene may list, and those this build runs: the registered ones (effect.hpp).
const std::vector<std::string>& valid_effects();

/// The discretisation of the scene's geometry (grid, or the model file's points).
solver::Discretization make_discretization(const Scene& s);

/// Reads and validates a scene file. Throws InputError naming file, line and key.
Scene load_scene(const std::filesystem::path& file);

/// The material the solver uses for this scene: the Neo-Hookean law of the given moduli
/// (plane strain / plane stress / 3D), or the Cauchy–Born material of the model file
/// (body::CauchyBornMaterial; a 2D model is its own areal, plane-strain material).
std::unique_ptr<solver::Material> make_material(const Scene& s);

/// The fully resolved scene as YAML (every default written out).
std::string resolved_yaml(const Scene& s);

/// Point indices selected by a region (throws InputError if none).
std::vector<int> select(const Scene& s, const solver::Discretization& body,
                        const BoundaryCondition& bc);
/// Offsets o_k of a `grip: surface` displacement set (docs/solver.md §4, "Grips on the
/// surface"): (Δx/2) n for every selected point whose grid cell has a face on the set's flat
/// face (outward normal n, the direction of Σ s_k over the set), 0 for the others. Needs a
/// cell-centred grid; InputError (with the key's line) otherwise or when the set's points
/// do not lie on one face of the box.
std::vector<solver::Vec3> surface_grip_offsets(const Scene& s, const solver::Discretization& body,
                                               const BoundaryCondition& bc,
                                               const std::vector<int>& points);

/// Runs the scene: per output step an HDF5 file (results_NNNN.h5) with the XDMF
/// time series results.xdmf, reactions.csv (dynamic: series.csv) and scene.resolved.yaml
/// in the output directory (`out_override` replaces output.directory).
void run_scene(const Scene& s, const std::optional<std::filesystem::path>& out_override = {});
/// Same, with a restart: the output directory is the restart directory, and the run
/// continues from its last checkpoint (InputError if there is none or the scene differs).
void run_scene(const Scene& s, const RunOptions& options);

}  // namespace pdcg::scene
