/// \file
/// Typed reads of the scene file for the components (file:line, key, value, expected, fix),
/// the component list of the scene core and the registries' internals. Private to the scene
/// module.
#pragma once

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/scene/component.hpp"
#include "pdcg/scene/effect.hpp"
#include "pdcg/scene/material_model.hpp"
#include "pdcg/scene/scene.hpp"

namespace pdcg::scene {

/// Shorthands of the components' number rules: the unbounded limit and the rule kinds.
inline constexpr double inf = std::numeric_limits<double>::infinity();
using K = NumberRule::Kind;

struct Ctx {
  std::string file;
  InputError err(const YAML::Node& n, const std::string& key, const std::string& problem) const;
  void keys(const YAML::Node& n, const std::string& where,
            const std::vector<std::string>& valid) const;
  double number(const YAML::Node& n, const std::string& key) const;
  int integer(const YAML::Node& n, const std::string& key) const;
  std::string text(const YAML::Node& n, const std::string& key) const;
  solver::Vec3 vec(const YAML::Node& n, const std::string& key, int dim) const;
  std::string choice(const YAML::Node& n, const std::string& key,
                     const std::vector<std::string>& valid) const;
  /// A boolean key ("not a boolean" … "true or false").
  bool boolean(const YAML::Node& n, const std::string& key) const;
};

/// A boundary value: a number or an expression in t.
std::function<double(double)> value_fn(const Ctx& c, const YAML::Node& n, const std::string& key,
                                       std::string& text);

inline bool has_effect(const Scene& s, const std::string& name) {
  return std::find(s.effects.begin(), s.effects.end(), name) != s.effects.end();
}

/// Fresh instances of the scene core's components (units…output, the effects list), in order.
std::vector<std::unique_ptr<Component>> core_components();

/// The built-in registrations (called by the registries before their first use).
void register_builtin_effects(const std::function<void(std::string, EffectFactory)>& add);
void register_builtin_materials(const std::function<void(std::string, MaterialFactory)>& add);

/// The first `dim` components of v as a flow sequence ([x, y] or [x, y, z]) of a resolved scene.
void emit_vec(YAML::Emitter& y, const solver::Vec3& v, int dim);

}  // namespace pdcg::scene
