// The files of a run: fields, XDMF, checkpoints (results.hpp).
#include "results.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <cstdint>
#include <numeric>

#include "checks.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace pdcg::scene {

namespace {

std::filesystem::path checkpoint_path(const std::filesystem::path& dir, long step) {
  return dir / fmt::format("checkpoint_{:08d}.h5", step);
}

/// Highest-numbered complete checkpoint in dir (temporaries never match the name).
std::optional<std::filesystem::path> last_checkpoint(const std::filesystem::path& dir) {
  std::optional<std::filesystem::path> best;
  long best_n = -1;
  if (!std::filesystem::is_directory(dir)) return best;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.size() != 22 || name.rfind("checkpoint_", 0) != 0 || name.substr(19) != ".h5")
      continue;
    const std::string digits = name.substr(11, 8);
    if (digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const long n = std::stol(digits);
    if (n > best_n) best_n = n, best = e.path();
  }
  return best;
}

std::string scene_identity(const Scene& s) {
  Scene c = s;
  c.output_directory = "";  // the restart directory replaces it
  return resolved_yaml(c);
}

}  // namespace

void write_xdmf(const std::filesystem::path& dir, std::size_t n,
                const std::vector<std::pair<int, double>>& steps, bool damage, bool velocity) {
  io::AtomicTextFile f(dir / "results.xdmf");
  auto& o = f.stream();
  o << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
       "  <Grid Name=\"pdcg\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& [step, t] : steps) {
    const std::string h5 = fmt::format("results_{:04d}.h5", step);
    o << fmt::format("   <Grid Name=\"step {}\" GridType=\"Uniform\">\n    <Time Value=\"{}\"/>\n",
                     step, t);
    // one vertex cell per point (connectivity points/vertex): without cells ParaView reads
    // the points but draws nothing
    o << fmt::format(
        "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" NodesPerElement=\"1\">"
        "<DataItem Dimensions=\"{} 1\" NumberType=\"Int\" Precision=\"8\" "
        "Format=\"HDF\">{}:/points/vertex</DataItem></Topology>\n",
        n, n, h5);
    o << fmt::format(
        "    <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"{} 3\" "
        "NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{}:/points/reference</DataItem>"
        "</Geometry>\n",
        n, h5);
    auto attr = [&](const char* name, const char* path, const char* type, int comps) {
      o << fmt::format(
          "    <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\"><DataItem "
          "Dimensions=\"{}{}\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">{}:{}</DataItem>"
          "</Attribute>\n",
          name, type, n, comps > 1 ? fmt::format(" {}", comps) : std::string(), h5, path);
    };
    attr("displacement", "/fields/displacement", "Vector", 3);
    attr("deformed_position", "/fields/deformed_position", "Vector", 3);
    attr("deformation_gradient", "/fields/deformation_gradient", "Tensor", 9);
    attr("first_piola_kirchhoff", "/fields/first_piola_kirchhoff", "Tensor", 9);
    attr("cauchy_stress", "/fields/cauchy_stress", "Tensor", 9);
    attr("energy_density", "/fields/energy_density", "Scalar", 1);
    if (velocity) attr("velocity", "/fields/velocity", "Vector", 3);
    if (damage) attr("damage", "/fields/damage", "Scalar", 1);
    o << "   </Grid>\n";
  }
  o << "  </Grid>\n </Domain>\n</Xdmf>\n";
  f.commit();
}

void write_fields(const std::filesystem::path& dir, const Scene& s,
                  const solver::Discretization& body, const solver::Model& model,
                  const solver::Material& material, const Eigen::VectorXd& u,
                  const Eigen::VectorXd* v, bool damage, int step,
                  const std::function<void(io::H5Writer&)>& attributes) {
  const int d = s.dimension;
  const std::size_t N = body.size();
  const auto F = model.point_deformation_gradients(u);
  std::vector<double> X(3 * N), U(3 * N, 0.0), Y(3 * N), Fv(9 * N), Pv(9 * N), Sv(9 * N), W(N);
  std::vector<double> V(v ? 3 * N : 0, 0.0);
  for (std::size_t i = 0; i < N; ++i) {
    for (int a = 0; a < 3; ++a) {
      X[3 * i + a] = body.positions()[i](a);
      if (a < d) U[3 * i + a] = u[d * i + a];
      if (v && a < d) V[3 * i + a] = (*v)[d * i + a];
      Y[3 * i + a] = X[3 * i + a] + U[3 * i + a];
    }
    double psi = 0;
    solver::Mat3 P = solver::Mat3::Zero();
    material.evaluate_at(static_cast<int>(i), F[i], &psi, &P, nullptr);
    const solver::Mat3 Ff = material.full_deformation_gradient(F[i]);
    const solver::Mat3 sigma = P * Ff.transpose() / Ff.determinant();
    for (int a = 0; a < 3; ++a)
      for (int J = 0; J < 3; ++J) {
        Fv[9 * i + 3 * a + J] = Ff(a, J);
        Pv[9 * i + 3 * a + J] = P(a, J);
        Sv[9 * i + 3 * a + J] = sigma(a, J);
      }
    W[i] = psi;
  }
  io::H5Writer h5(dir / fmt::format("results_{:04d}.h5", step),
                  {"pdcg-results", 1, s.units, {}, {}});
  h5.write("points/reference", X, {N, 3});
  h5.write("points/volume", body.volumes(), {N});
  std::vector<std::int64_t> vertex(N);  // the XDMF's vertex cells (write_xdmf)
  std::iota(vertex.begin(), vertex.end(), std::int64_t{0});
  h5.write("points/vertex", vertex, {N, 1});
  h5.write("fields/displacement", U, {N, 3});
  h5.write("fields/deformed_position", Y, {N, 3});
  h5.write("fields/deformation_gradient", Fv, {N, 9});
  h5.write("fields/first_piola_kirchhoff", Pv, {N, 9});
  h5.write("fields/cauchy_stress", Sv, {N, 9});
  h5.write("fields/energy_density", W, {N});
  if (v) h5.write("fields/velocity", V, {N, 3});
  if (damage) h5.write("fields/damage", body.damage(), {N});
  attributes(h5);
  h5.commit();
}

// ------------------------------------------------------------------ checkpoints
//
// checkpoint_NNNNNNNN.h5 (format pdcg-checkpoint) in the output directory, written
// atomically (H5Writer: temporary + rename) after the outputs of step N; the previous one
// is deleted only after the new one is in place, so a kill at any moment leaves at least
// one complete checkpoint. It holds the complete solver state, the series text written so
// far and the list of field files, and the resolved scene (a restart refuses another scene).

Restart load_checkpoint(const Scene& s, const std::filesystem::path& dir) {
  const auto file = last_checkpoint(dir);
  if (!file)
    throw InputError("no checkpoint to restart from")
        .source(dir.string())
        .key("--restart")
        .expected(
            "a directory holding checkpoint_NNNNNNNN.h5 (written with "
            "output: {checkpoint_every: N})")
        .fix("check the directory, or run without --restart");
  Restart r;
  r.file = *file;
  try {
    // every dataset against its checksum before any is used: a damaged checkpoint (a copy cut
    // short, a disk error) is refused, never restarted from
    r.h5 = std::make_unique<io::H5Reader>(*file);
    r.h5->verify();
  } catch (const InputError& e) {
    throw InputError(std::string("the checkpoint is truncated or corrupt: ") + e.what())
        .source(file->string())
        .key("--restart")
        .fix(
            "run the scene again from the start (without --restart, into another directory), "
            "or put back an intact copy of the checkpoint");
  }
  r.h5->require_format("pdcg-checkpoint", 1);
  r.kind = r.h5->attribute_string("/", "kind");
  r.step = static_cast<long>(r.h5->attribute_int("/", "step"));
  r.t = r.h5->attribute_double("/", "t");
  if (r.h5->read_string("scene") != scene_identity(s))
    throw InputError("the checkpoint was written by another scene")
        .source(file->string())
        .key("--restart")
        .expected(fmt::format("the scene of {} (see scene.resolved.yaml there)", dir.string()))
        .fix("restart with the scene file of the interrupted run");
  r.series = r.h5->read_string("series");
  const auto ws = r.h5->read_int("written/steps");
  const auto wt = r.h5->read_double("written/times");
  for (std::size_t i = 0; i < ws.size(); ++i)
    r.written.emplace_back(static_cast<int>(ws[i]), wt[i]);
  log::info("restart from {}: step {}, t = {:.6g}", file->string(), r.step, r.t);
  return r;
}

std::unique_ptr<io::H5Writer> begin_checkpoint(const Scene& s, const std::filesystem::path& dir,
                                               const char* kind, long step, double t,
                                               const std::string& series,
                                               const std::vector<std::pair<int, double>>& written) {
  auto h5 = std::make_unique<io::H5Writer>(checkpoint_path(dir, step),
                                           io::FileInfo{"pdcg-checkpoint", 1, s.units, {}, {}});
  h5->attribute("/", "kind", kind);
  h5->attribute("/", "step", static_cast<std::int64_t>(step));
  h5->attribute("/", "t", t);
  h5->write("scene", scene_identity(s));
  h5->write("series", series);
  std::vector<std::int64_t> ws;
  std::vector<double> wt;
  for (const auto& [n, tw] : written) ws.push_back(n), wt.push_back(tw);
  h5->write("written/steps", ws);
  h5->write("written/times", wt);
  return h5;
}

void finish_checkpoint(io::H5Writer& h5, const std::filesystem::path& dir, long step) {
  h5.commit();
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("checkpoint_", 0) == 0 && name.size() == 22 && name.substr(19) == ".h5" &&
        e.path() != checkpoint_path(dir, step))
      std::filesystem::remove(e.path());
  }
}

InputError& with_line(const Scene& s, InputError& e) {
  e.source(s.source.string());
  if (const long l = checks::line_of(s, e.key_name()); l > 0 && e.line_number() == 0) e.line(l);
  return e;
}

EffectRuns attach_effects(const Scene& s, const RunContext& context) {
  EffectRuns runs;
  for (const auto& e : s.effect_objects)
    if (auto run = e->attach(context)) {
      log::info("effect {}: {} column{}", e->name(), run->columns().size(),
                run->columns().size() == 1 ? "" : "s");
      runs.emplace_back(e->name(), std::move(run));
    }
  return runs;
}

std::string effect_values(const EffectRuns& runs, const StepState& state, const char* format) {
  std::string out;
  for (const auto& [name, run] : runs) {
    std::vector<double> values;
    run->on_step(state, values);
    if (values.size() != run->columns().size())
      throw Error(fmt::format("effect {} gave {} values for {} columns", name, values.size(),
                              run->columns().size()));
    for (double v : values) {
      out.push_back(',');
      fmt::format_to(std::back_inserter(out), fmt::runtime(format), v);
    }
  }
  return out;
}

Eigen::VectorXd vec_of(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}
std::vector<double> std_of(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

}  // namespace pdcg::scene
