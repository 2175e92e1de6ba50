/// \file
/// The parts a scene is made of (docs/architecture.md, "Scene components"): every root section
/// of a scene file is owned by one component (geometry, material, boundary, loading, solver,
/// output, and each effect), which declares its numeric keys, parses and validates its section
/// and writes its part of scene.resolved.yaml. load_scene and resolved_yaml only walk the
/// components in order; the list of root keys is the union of the sections they declare.
///
/// Components see the scene file through `Node` (a key of the file with its line) and `Reader`
/// (typed reads that throw InputError naming file:line, key, value, expected and fix), and write
/// through `Emitter`; yaml-cpp stays private to the scene module.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/point_cloud.hpp"

namespace YAML {
class Node;
class Emitter;
}  // namespace YAML

namespace pdcg::scene {

struct Scene;

/// A node of the scene file (a mapping, a list or a value) with its line.
class Node {
 public:
  Node();
  explicit Node(const YAML::Node& n);
  bool defined() const;
  explicit operator bool() const { return defined(); }
  bool is_map() const;
  bool is_sequence() const;
  bool is_scalar() const;
  std::size_t size() const;
  Node operator[](const std::string& key) const;  ///< undefined if absent
  Node operator[](std::size_t index) const;
  std::string scalar() const;  ///< the text of a value ("" for a mapping or a list)
  long line() const;           ///< 1-based; 0 if unknown
  const YAML::Node& yaml() const;

 private:
  std::shared_ptr<const YAML::Node> n_;
};

/// Typed reads of a scene file: each throws an InputError naming the file, the line of the
/// node, the key, the bad value, what was expected (and, where one is known, the fix).
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }
  /// An InputError at node n (file:line: key: problem); add .value/.expected/.fix.
  InputError error(const Node& n, const std::string& key, const std::string& problem) const;
  /// n is a mapping whose keys are all in `valid` ("unknown key … one of: …").
  void keys(const Node& n, const std::string& where, const std::vector<std::string>& valid) const;
  double number(const Node& n, const std::string& key) const;
  int integer(const Node& n, const std::string& key) const;
  bool boolean(const Node& n, const std::string& key) const;
  std::string text(const Node& n, const std::string& key) const;
  std::string choice(const Node& n, const std::string& key,
                     const std::vector<std::string>& valid) const;
  solver::Vec3 vec(const Node& n, const std::string& key, int dim) const;

 private:
  std::string file_;
};

/// scene.resolved.yaml under construction (15 significant digits, the scene's own style).
class Emitter {
 public:
  explicit Emitter(YAML::Emitter& y) : y_(&y) {}
  /// `key: {` — a flow mapping; close it with end_map().
  Emitter& begin_map(const std::string& key);
  Emitter& end_map();
  Emitter& value(const std::string& key, double v);
  Emitter& value(const std::string& key, int v);
  Emitter& value(const std::string& key, bool v);
  Emitter& value(const std::string& key, const std::string& v);
  Emitter& value(const std::string& key, const char* v) { return value(key, std::string(v)); }
  YAML::Emitter& yaml() { return *y_; }

 private:
  YAML::Emitter* y_;
};

/// One numeric key of a section: its path ("a.b[].c": [] = every item of the list a.b), its
/// kind and the accepted range [lo, hi] (open at an end when lo_open / hi_open). Every number a
/// scene reads has one (checked before any section is parsed, in the order of the sections).
struct NumberRule {
  enum class Kind {
    real,         ///< a finite number
    integer,      ///< an integer (2.5 is refused, not truncated)
    real_or_fn,   ///< a finite number, or an expression (checked where it is evaluated)
    real_or_auto  ///< a finite number or the word auto
  };
  std::string path;
  Kind kind = Kind::real;
  double lo = -std::numeric_limits<double>::infinity();
  bool lo_open = true;
  double hi = std::numeric_limits<double>::infinity();
  bool hi_open = true;
  std::string expected;
};

/// The numeric rules of every component and registered effect, in the order they are checked.
std::vector<NumberRule> number_rules();

/// A root section a component owns, with its place in the parse order and in the resolved
/// scene (lower first; equal ranks keep the order of registration).
struct Section {
  std::string key;
  int parse_rank = 0;
  int resolved_rank = 0;
};

/// A part of a scene: its root sections, their numeric keys, their parsing and validation, and
/// their part of the resolved scene.
class Component {
 public:
  virtual ~Component() = default;
  virtual std::vector<Section> sections() const = 0;
  /// Numeric keys (type, sign, range, finiteness), checked before any section is parsed.
  virtual std::vector<NumberRule> number_rules() const { return {}; }
  /// Parses and validates `section` of `root` into s. Called for every section in parse order,
  /// also when the file does not give it (defaults, required sections).
  virtual void parse(const std::string& section, const Reader& r, const Node& root, Scene& s) = 0;
  /// Writes `section` of the resolved scene (nothing when it does not apply to s).
  virtual void resolve(const std::string& section, Emitter& out, const Scene& s) const = 0;
};

}  // namespace pdcg::scene

#define PDCG_SCENE_CONCAT_(a, b) a##b
#define PDCG_SCENE_CONCAT(a, b) PDCG_SCENE_CONCAT_(a, b)
