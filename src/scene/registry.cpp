// The effect and material registries: the built-in entries come from explicit registration
// functions (register_builtin_effects / _materials), called before the first use, so that a
// static link of the scene library cannot drop them; PDCG_REGISTER_EFFECT / _MATERIAL add
// entries after them, in order of registration.
#include <mutex>

#include "parse.hpp"

namespace pdcg::scene {

namespace {

template <class Factory>
struct Registry {
  std::vector<std::pair<std::string, Factory>> builtin, added;
  std::once_flag once;
  const Factory* find(const std::string& name) const {
    for (const auto* list : {&builtin, &added})
      for (const auto& [n, f] : *list)
        if (n == name) return &f;
    return nullptr;
  }
  std::vector<std::string> names() const {
    std::vector<std::string> v;
    for (const auto* list : {&builtin, &added})
      for (const auto& e : *list) v.push_back(e.first);
    return v;
  }
};

Registry<EffectFactory>& effects() {
  static Registry<EffectFactory> r;
  std::call_once(r.once, [] {
    register_builtin_effects(
        [](std::string n, EffectFactory f) { r.builtin.emplace_back(std::move(n), std::move(f)); });
  });
  return r;
}

Registry<MaterialFactory>& materials() {
  static Registry<MaterialFactory> r;
  std::call_once(r.once, [] {
    register_builtin_materials([](std::string n, MaterialFactory f) {
      r.builtin.emplace_back(std::move(n), std::move(f));
    });
  });
  return r;
}

std::string scene_word(std::string name) {
  std::replace(name.begin(), name.end(), '_', '-');
  return name;
}

}  // namespace

bool Effect::listed(const Scene& s) const { return has_effect(s, name()); }

bool register_effect(const std::string& name, EffectFactory factory) {
  auto& r = effects();
  if (r.find(name)) throw Error("effect registered twice: " + name);
  r.added.emplace_back(name, std::move(factory));
  return true;
}

std::vector<std::string> registered_effects() { return effects().names(); }

std::unique_ptr<Effect> make_effect(const std::string& name) {
  const auto* f = effects().find(name);
  if (!f) return nullptr;
  auto e = (*f)();
  e->set_name(name);
  return e;
}

bool register_material(const std::string& name, MaterialFactory factory) {
  auto& r = materials();
  const std::string word = scene_word(name);
  if (r.find(word)) throw Error("material model registered twice: " + word);
  r.added.emplace_back(word, std::move(factory));
  return true;
}

std::vector<std::string> registered_materials() { return materials().names(); }

std::unique_ptr<MaterialModel> make_material_model(const std::string& name) {
  const auto* f = materials().find(name);
  if (!f) return nullptr;
  auto m = (*f)();
  m->set_name(name);
  return m;
}

const std::vector<std::string>& valid_effects() {
  // registrations happen before main (static initialisers) or on first use: a copy per call
  // would dangle, so the list is kept and refreshed when the registry grew
  static std::vector<std::string> v;
  static std::mutex m;
  std::lock_guard lock(m);
  auto names = registered_effects();
  if (names != v) v = std::move(names);
  return v;
}

}  // namespace pdcg::scene
