#include "parse.hpp"

#include "pdcg/scene/expression.hpp"

namespace pdcg::scene {

InputError Ctx::err(const YAML::Node& n, const std::string& key, const std::string& problem) const {
  InputError e(problem);
  e.source(file).key(key);
  if (n.IsDefined() && n.Mark().line >= 0) e.line(n.Mark().line + 1);
  return e;
}

void Ctx::keys(const YAML::Node& n, const std::string& where,
               const std::vector<std::string>& valid) const {
  if (!n.IsDefined())  // an absent node: its IsMap() would throw YAML::InvalidNode
    throw err(n, where, "missing key").expected(fmt::format("keys {}", fmt::join(valid, ", ")));
  if (!n.IsMap())
    throw err(n, where, "expected a mapping {key: value, ...}")
        .expected(fmt::format("keys {}", fmt::join(valid, ", ")));
  for (const auto& kv : n) {
    if (!kv.first.IsScalar())  // e.g. `{!tag: 1}` or `{[a, b]: 1}`: as<std::string> would throw
      throw err(kv.first, where, "a key must be a plain name")
          .expected(fmt::format("one of: {}", fmt::join(valid, ", ")));
    const std::string k = kv.first.as<std::string>();
    if (std::find(valid.begin(), valid.end(), k) == valid.end())
      throw err(kv.first, where.empty() ? k : where + "." + k, "unknown key")
          .value(k)
          .expected(fmt::format("one of: {}", fmt::join(valid, ", ")));
  }
}

namespace {
// A required key that is absent: yaml-cpp hands back an invalid node whose type queries throw
// YAML::InvalidNode, so every accessor asks IsDefined() (which does not throw) first.
void require_defined(const Ctx& c, const YAML::Node& n, const std::string& key,
                     const std::string& expected) {
  if (!n.IsDefined()) throw c.err(n, key, "missing key").expected(expected);
}
}  // namespace

double Ctx::number(const YAML::Node& n, const std::string& key) const {
  require_defined(*this, n, key, "a number");
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    throw err(n, key, "not a number")
        .value(n.IsScalar() ? n.Scalar() : "(not a scalar)")
        .expected("a number");
  }
}

int Ctx::integer(const YAML::Node& n, const std::string& key) const {
  require_defined(*this, n, key, "an integer");
  try {
    return n.as<int>();
  } catch (const YAML::Exception&) {
    throw err(n, key, "not an integer")
        .value(n.IsScalar() ? n.Scalar() : "(not a scalar)")
        .expected("an integer");
  }
}

std::string Ctx::text(const YAML::Node& n, const std::string& key) const {
  require_defined(*this, n, key, "a string");
  if (!n.IsScalar()) throw err(n, key, "expected a single value").expected("a string");
  return n.Scalar();
}

solver::Vec3 Ctx::vec(const YAML::Node& n, const std::string& key, int dim) const {
  require_defined(
      *this, n, key,
      fmt::format("a list of {} numbers, e.g. [0.0, 0.0{}]", dim, dim == 3 ? ", 0.0" : ""));
  if (!n.IsSequence() || static_cast<int>(n.size()) != dim)
    throw err(n, key, "wrong vector")
        .expected(
            fmt::format("a list of {} numbers, e.g. [0.0, 0.0{}]", dim, dim == 3 ? ", 0.0" : ""));
  solver::Vec3 v = solver::Vec3::Zero();
  for (int a = 0; a < dim; ++a) v(a) = number(n[a], key);
  return v;
}

std::string Ctx::choice(const YAML::Node& n, const std::string& key,
                        const std::vector<std::string>& valid) const {
  const std::string v = text(n, key);
  if (std::find(valid.begin(), valid.end(), v) == valid.end())
    throw err(n, key, "invalid value")
        .value(v)
        .expected(fmt::format("one of: {}", fmt::join(valid, ", ")));
  return v;
}

bool Ctx::boolean(const YAML::Node& n, const std::string& key) const {
  require_defined(*this, n, key, "true or false");
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    throw err(n, key, "not a boolean")
        .value(n.IsScalar() ? n.Scalar() : "")
        .expected("true or false");
  }
}

std::function<double(double)> value_fn(const Ctx& c, const YAML::Node& n, const std::string& key,
                                       std::string& text) {
  require_defined(c, n, key, "a number or an expression in t");
  if (!n.IsScalar()) throw c.err(n, key, "expected a number or an expression in t");
  text = n.Scalar();
  try {
    const double v = n.as<double>();
    return [v](double) { return v; };
  } catch (const YAML::Exception&) {
  }
  try {
    return parse_expression(text, key);
  } catch (InputError& e) {
    throw e.source(c.file).line(n.Mark().line + 1);
  }
}

// ------------------------------------------------------------------ public wrappers

Node::Node() : n_(std::make_shared<const YAML::Node>(YAML::NodeType::Undefined)) {}
Node::Node(const YAML::Node& n) : n_(std::make_shared<const YAML::Node>(n)) {}
bool Node::defined() const { return n_->IsDefined(); }
bool Node::is_map() const { return n_->IsMap(); }
bool Node::is_sequence() const { return n_->IsSequence(); }
bool Node::is_scalar() const { return n_->IsScalar(); }
std::size_t Node::size() const { return n_->size(); }
Node Node::operator[](const std::string& key) const {
  if (!n_->IsMap()) return Node();
  return Node((*n_)[key]);
}
Node Node::operator[](std::size_t index) const {
  if (!n_->IsSequence() || index >= n_->size()) return Node();
  return Node((*n_)[index]);
}
std::string Node::scalar() const { return n_->IsScalar() ? n_->Scalar() : std::string(); }
long Node::line() const {
  return n_->IsDefined() && n_->Mark().line >= 0 ? n_->Mark().line + 1 : 0;
}
const YAML::Node& Node::yaml() const { return *n_; }

InputError Reader::error(const Node& n, const std::string& key, const std::string& problem) const {
  return Ctx{file_}.err(n.yaml(), key, problem);
}
void Reader::keys(const Node& n, const std::string& where,
                  const std::vector<std::string>& valid) const {
  Ctx{file_}.keys(n.yaml(), where, valid);
}
double Reader::number(const Node& n, const std::string& key) const {
  return Ctx{file_}.number(n.yaml(), key);
}
int Reader::integer(const Node& n, const std::string& key) const {
  return Ctx{file_}.integer(n.yaml(), key);
}
bool Reader::boolean(const Node& n, const std::string& key) const {
  return Ctx{file_}.boolean(n.yaml(), key);
}
std::string Reader::text(const Node& n, const std::string& key) const {
  return Ctx{file_}.text(n.yaml(), key);
}
std::string Reader::choice(const Node& n, const std::string& key,
                           const std::vector<std::string>& valid) const {
  return Ctx{file_}.choice(n.yaml(), key, valid);
}
solver::Vec3 Reader::vec(const Node& n, const std::string& key, int dim) const {
  return Ctx{file_}.vec(n.yaml(), key, dim);
}

Emitter& Emitter::begin_map(const std::string& key) {
  *y_ << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
  return *this;
}
Emitter& Emitter::end_map() {
  *y_ << YAML::EndMap;
  return *this;
}
Emitter& Emitter::value(const std::string& key, double v) {
  *y_ << YAML::Key << key << YAML::Value << v;
  return *this;
}
Emitter& Emitter::value(const std::string& key, int v) {
  *y_ << YAML::Key << key << YAML::Value << v;
  return *this;
}
Emitter& Emitter::value(const std::string& key, bool v) {
  *y_ << YAML::Key << key << YAML::Value << v;
  return *this;
}
Emitter& Emitter::value(const std::string& key, const std::string& v) {
  *y_ << YAML::Key << key << YAML::Value << v;
  return *this;
}

void emit_vec(YAML::Emitter& y, const solver::Vec3& v, int dim) {
  y << YAML::Flow << YAML::BeginSeq;
  for (int a = 0; a < dim; ++a) y << v(a);
  y << YAML::EndSeq;
}

}  // namespace pdcg::scene
