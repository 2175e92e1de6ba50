/// \file
/// Material models of a scene (`material: {model: NAME, ...}`) and their registry.
///
/// A material model declares the keys of `material:` it takes (with their numeric rules),
/// parses and validates them, writes them to the resolved scene and builds the
/// solver::Material the run uses. Register one with a line at namespace scope of a source file
/// linked into the executable:
/// \code
///   PDCG_REGISTER_MATERIAL(st_venant_kirchhoff, MyMaterial)
/// \endcode
/// (tests/unit/scene/test_registries.cpp does it). In a scene file the model is written with
/// '-' for '_' (st-venant-kirchhoff). The built-in models (neo-hookean, cauchy-born) are
/// registered by an explicit list in the scene library.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/scene/component.hpp"
#include "pdcg/solver/material.hpp"

namespace pdcg::scene {

class MaterialModel {
 public:
  virtual ~MaterialModel() = default;
  /// The keys of `material:` it takes besides `model` (density included if it reads it).
  virtual std::vector<std::string> keys() const = 0;
  virtual std::vector<NumberRule> number_rules() const { return {}; }
  /// Parses `material:` (m) into s and into the model itself (its own parameters). Called
  /// after material.density (when given) is read into s.density.
  virtual void parse(const Reader& r, const Node& m, Scene& s) = 0;
  /// Its keys in the resolved `material:` mapping, after `model` and before `density`.
  virtual void resolve(Emitter& out, const Scene& s) const = 0;
  /// The material of the run.
  virtual std::unique_ptr<solver::Material> make(const Scene& s) const = 0;
  /// The scene name (`material.model`), set by the registry.
  const std::string& name() const { return name_; }
  void set_name(std::string n) { name_ = std::move(n); }

 private:
  std::string name_;
};

using MaterialFactory = std::function<std::unique_ptr<MaterialModel>()>;

/// Adds a material model (a duplicate name throws pdcg::Error). Returns true.
bool register_material(const std::string& name, MaterialFactory factory);
/// The registered models, built-in first (neo-hookean, cauchy-born).
std::vector<std::string> registered_materials();
/// A fresh instance of a registered model (null if unknown).
std::unique_ptr<MaterialModel> make_material_model(const std::string& name);

}  // namespace pdcg::scene

/// Registers material model `Type` (default-constructible, derived from
/// pdcg::scene::MaterialModel) as `name` (an identifier; '_' reads '-' in scene files).
#define PDCG_REGISTER_MATERIAL(name, Type)                                          \
  namespace {                                                                       \
  const bool PDCG_SCENE_CONCAT(pdcg_material_registered_,                           \
                               name) = ::pdcg::scene::register_material(#name, [] { \
    return std::make_unique<Type>();                                                \
  });                                                                               \
  }
