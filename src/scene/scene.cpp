// load_scene and resolved_yaml: the scene core walks the components (core_sections.cpp,
// geometry.cpp, material.cpp, boundary.cpp) and the registered effects (effects_builtin.cpp and
// any PDCG_REGISTER_EFFECT) in the order of their sections; it holds no key of its own.
#include "pdcg/scene/scene.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <map>

#include "checks.hpp"
#include "parse.hpp"

namespace pdcg::scene {

namespace {

/// The components of one load or write: the core, then every registered effect (the parsed
/// instances of a scene's listed effects when given).
struct Parts {
  std::vector<std::unique_ptr<Component>> core;
  std::vector<std::shared_ptr<Effect>> effects;
  struct Entry {
    Component* component;
    Section section;
  };
  /// Root keys in order: the core's sections, each effect's own section in the registry's
  /// order, then the further sections of effects (inertia's `initial`).
  std::vector<Entry> keyed() const {
    std::vector<Entry> v, later;
    for (const auto& c : core)
      for (const auto& s : c->sections()) v.push_back({c.get(), s});
    for (const auto& e : effects) {
      const auto secs = e->sections();
      for (std::size_t i = 0; i < secs.size(); ++i)
        (i == 0 ? v : later).push_back({e.get(), secs[i]});
    }
    v.insert(v.end(), later.begin(), later.end());
    return v;
  }
  std::vector<Entry> by(int Section::*rank) const {
    auto v = keyed();
    std::stable_sort(v.begin(), v.end(), [&](const Entry& a, const Entry& b) {
      return a.section.*rank < b.section.*rank;
    });
    return v;
  }
};

Parts parts(const Scene* s) {
  Parts p;
  p.core = core_components();
  for (const auto& name : registered_effects()) {
    std::shared_ptr<Effect> e;
    if (s)
      for (const auto& o : s->effect_objects)
        if (o->name() == name) e = std::const_pointer_cast<Effect>(o);
    p.effects.push_back(e ? e : std::shared_ptr<Effect>(make_effect(name)));
  }
  return p;
}

/// The components' numeric rules, in the order of the root keys (a rule's section is the first
/// segment of its path).
std::vector<NumberRule> rules_of(const Parts& p) {
  const auto keyed = p.keyed();
  std::map<std::string, std::vector<NumberRule>> by_section;
  std::vector<const Component*> seen;
  for (const auto& e : keyed) {
    if (std::find(seen.begin(), seen.end(), e.component) != seen.end()) continue;
    seen.push_back(e.component);
    for (auto& r : e.component->number_rules())
      by_section[r.path.substr(0, r.path.find_first_of(".["))].push_back(std::move(r));
  }
  std::vector<NumberRule> rules;
  for (const auto& e : keyed)
    for (auto& r : by_section[e.section.key]) rules.push_back(std::move(r));
  return rules;
}

}  // namespace

std::vector<NumberRule> number_rules() { return rules_of(parts(nullptr)); }

Scene load_scene(const std::filesystem::path& file) {
  Ctx c{file.string()};
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::BadFile&) {
    throw InputError("cannot open the scene file").source(file.string()).fix("check the path");
  } catch (const YAML::ParserException& e) {
    throw InputError("YAML syntax error: " + e.msg).source(file.string()).line(e.mark.line + 1);
  }
  Scene s;
  s.source = file;
  const Parts p = parts(nullptr);
  const auto keyed = p.keyed();
  std::vector<std::string> keys;
  for (const auto& e : keyed) keys.push_back(e.section.key);
  c.keys(root, "", keys);
  // every number first, from the components' rules: type, sign, range, finite
  checks::numbers(root, c.file, rules_of(p));
  s.key_lines = checks::key_lines(root);
  const Reader reader(c.file);
  const Node rootn(root);
  for (const auto& e : p.by(&Section::parse_rank)) {
    e.component->parse(e.section.key, reader, rootn, s);
    if (e.section.key != "effects") continue;
    // the listing: a section of an effect the scene does not list, then each effect's own
    // checks (e.g. damping without inertia)
    for (const auto& eff : p.effects) {
      const std::string sec = eff->sections().front().key;
      if (root[sec] && !has_effect(s, eff->name()))
        throw c.err(root[sec], sec, "settings for an effect the scene does not list")
            .expected(fmt::format("'{}' in effects: [...] when a '{}:' section is given", sec, sec))
            .fix(fmt::format("add {} to effects, or remove the {} section", sec, sec));
    }
    for (const auto& eff : p.effects) eff->check_listing(reader, rootn, s);
  }
  for (const auto& eff : p.effects)
    if (eff->listed(s)) s.effect_objects.push_back(eff);
  checks::consistency(s);  // contradictions between keys (empty regions, non-finite values)
  // relative output directory: relative to the working directory (like every CLI path)
  return s;
}

std::string resolved_yaml(const Scene& s) {
  YAML::Emitter y;
  y.SetDoublePrecision(15);
  Emitter out(y);
  y << YAML::BeginMap;
  const Parts p = parts(&s);
  for (const auto& e : p.by(&Section::resolved_rank)) e.component->resolve(e.section.key, out, s);
  y << YAML::EndMap;
  return std::string(y.c_str()) + "\n";
}

}  // namespace pdcg::scene
