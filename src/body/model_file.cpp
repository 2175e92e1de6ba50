#include "pdcg/body/model_file.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/io/hdf5.hpp"

namespace pdcg::body {

namespace {

std::vector<std::int64_t> to64(const std::vector<int>& v) { return {v.begin(), v.end()}; }
template <class T>
std::vector<std::int64_t> to64(const std::vector<T>& v, int) {
  return {v.begin(), v.end()};
}

template <class T>
std::vector<T> narrow(const std::vector<std::int64_t>& v) {
  return {v.begin(), v.end()};
}

/// Narrowing with a range check (the file stores int64; the body holds smaller integers).
template <class T>
std::vector<T> narrow_checked(const std::vector<std::int64_t>& v, const std::string& src,
                              std::string_view key, std::string_view why) {
  constexpr auto lo = static_cast<std::int64_t>(std::numeric_limits<T>::min()),
                 hi = static_cast<std::int64_t>(std::numeric_limits<T>::max());
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] < lo || v[i] > hi)
      throw InputError("value out of range")
          .source(src)
          .key(fmt::format("{}[{}]", key, i))
          .value(std::to_string(v[i]))
          .expected(fmt::format("{} … {} ({})", lo, hi, why))
          .fix(
              "the file was not written by a compatible pdcg, or the body is beyond the limits "
              "of docs/bodies.md");
  return {v.begin(), v.end()};
}

}  // namespace

std::vector<EmbeddedFile> embed_potential_files(const atomistic::PotentialSpec& spec) {
  std::vector<EmbeddedFile> out;
  for (const auto& c : spec.pair_coeff) {
    const std::string tok = atomistic::coeff_file_argument(spec, c);
    if (tok.empty()) continue;
    bool seen = false;
    for (const auto& e : out) seen = seen || e.name == tok;
    if (seen) continue;
    const auto path = atomistic::find_potential_file(tok);
    std::ifstream in(path.value_or(tok), std::ios::binary);
    if (!path || !in)
      throw InputError("potential file not found")
          .source(spec.source)
          .line(c.line_number)
          .key("pair_coeff")
          .value(tok)
          .expected("a file at the given path or in $LAMMPS_POTENTIALS")
          .fix("give the path of the potential file in the pair_coeff line");
    std::ostringstream ss;
    ss << in.rdbuf();
    out.push_back({tok, ss.str()});
  }
  return out;
}

std::shared_ptr<const atomistic::Potential> potential_from_commands(
    const atomistic::PotentialSpec& stored, const std::vector<EmbeddedFile>& files) {
  std::vector<std::string> lines = stored.lines;
  std::filesystem::path dir;
  if (!files.empty()) {
    dir = std::filesystem::temp_directory_path() / fmt::format("pdcg-potential-{}-{}",
                                                               static_cast<long>(::getpid()),
                                                               static_cast<const void*>(&files));
    std::filesystem::create_directories(dir);
    for (std::size_t k = 0; k < files.size(); ++k) {
      const auto target =
          dir / fmt::format("{}_{}", k, std::filesystem::path(files[k].name).filename().string());
      {
        // a full /tmp or `ulimit -f` must not leave a cut file that then reads as a damaged
        // potential: the write error, naming the file
        std::ofstream out(target, std::ios::binary);
        out << files[k].contents;
        out.flush();
        if (!out)
          io::throw_write_error(target, errno ? errno : EIO, "writing the embedded potential file");
      }
      for (auto& l : lines) {
        // replace the file word of pair_coeff lines (whole words only)
        if (l.find("pair_coeff") == std::string::npos) continue;
        std::string rebuilt;
        for (auto w : split_blanks(l)) {
          if (!rebuilt.empty()) rebuilt.push_back(' ');
          if (w == files[k].name)
            rebuilt.append(target.string());
          else
            rebuilt.append(w);
        }
        l = rebuilt;
      }
    }
  }
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  std::shared_ptr<const atomistic::Potential> pot;
  try {
    atomistic::PotentialSpec spec = atomistic::read_potential_commands_from_string(
        text, stored.source.empty() ? "model file" : stored.source, stored.ntypes);
    pot = atomistic::make_potential(spec);
  } catch (...) {
    if (!dir.empty()) std::filesystem::remove_all(dir);
    throw;
  }
  if (!dir.empty()) std::filesystem::remove_all(dir);
  return pot;
}

PotentialFactory& default_potential_factory() {
  static PotentialFactory f = potential_from_commands;
  return f;
}

void write_body(const Body& b, const std::filesystem::path& path) {
  io::FileInfo info;
  info.format = "pdcg-body";
  info.schema_version = kBodySchemaVersion;
  info.units = b.units;
  io::H5Writer w(path, info);
  const std::size_t n = b.size();
  w.attribute("/", "kind", to_string(b.kind));
  w.attribute("/", "dimension", static_cast<std::int64_t>(b.dimension));
  w.attribute("/", "epsilon", b.epsilon);
  w.attribute("/", "points", static_cast<std::int64_t>(n));
  // box
  w.write("box/lo", std::vector<double>{b.box.lo[0], b.box.lo[1], b.box.lo[2]});
  w.write("box/hi", std::vector<double>{b.box.hi[0], b.box.hi[1], b.box.hi[2]});
  w.write("box/tilt", std::vector<double>{b.box.xy, b.box.xz, b.box.yz});
  w.write("box/periodic",
          std::vector<std::int64_t>{b.box.periodic[0], b.box.periodic[1], b.box.periodic[2]});
  w.attribute("/box", "reference_volume", b.reference_volume());
  // atomic layer
  w.write("points/id", b.id);
  w.write("points/type", to64(b.type));
  w.write("points/x", b.x, {n, 3});
  w.write("points/mass", b.mass);
  const auto& f = b.families;
  const std::size_t nb = f.bonds();
  w.write("families/offset", f.offset);
  w.write("families/neighbor", to64(f.neighbor, 0));
  w.write("families/shift", to64(f.shift, 0), {nb, 3});
  // ξ is derived from the positions (the Families do not hold it); written for readers of
  // older pdcg versions and for tools, ignored on reading.
  w.write("families/xi", atomistic::bond_vectors(f, b.x), {nb, 3});
  w.write("families/reverse", to64(f.reverse, 0));
  if (!f.pair_factor.empty()) w.write("families/pair_factor", f.pair_factor);
  if (!f.bond_type.empty()) w.write("families/bond_type", to64(f.bond_type));
  const Eigen::Matrix3d h = f.h.transpose();  // row-major storage of H
  w.write("families/h", std::span<const double>(h.data(), 9), {3, 3});
  w.attribute("/families", "base_horizon", b.base_horizon);
  w.attribute("/families", "horizon", b.horizon());
  // potential
  const auto& s = b.potential_spec;
  w.write_strings("potential/lines", s.lines.empty() ? std::vector<std::string>{""} : s.lines);
  w.attribute("/potential", "style", b.base_potential ? b.base_potential->style() : std::string());
  w.attribute("/potential", "source", s.source);
  w.attribute("/potential", "atom_style", s.atom_style);
  w.attribute("/potential", "ntypes", static_cast<std::int64_t>(s.ntypes));
  w.attribute("/potential", "cutoff", b.base_potential ? b.base_potential->cutoff() : 0.0);
  if (!s.type_mass.empty()) w.write("potential/type_mass", s.type_mass);
  w.write("potential/special_lj", std::vector<double>(s.special_lj.begin(), s.special_lj.end()));
  w.write("potential/special_coul",
          std::vector<double>(s.special_coul.begin(), s.special_coul.end()));
  if (!b.potential_files.empty()) {
    std::vector<std::string> names, contents;
    for (const auto& e : b.potential_files) {
      names.push_back(e.name);
      contents.push_back(e.contents);
    }
    w.write_strings("potential/file_names", names);
    w.write_strings("potential/file_contents", contents);
  }
  // statistics
  if (b.statistics) {
    const auto& st = *b.statistics;
    w.attribute("/statistics", "form",
                st.form == Statistics::Form::gaussian ? "gaussian" : "empirical");
    w.attribute("/statistics", "method",
                st.method == Statistics::Method::cubature ? "cubature" : "sampling");
    w.attribute("/statistics", "order", static_cast<std::int64_t>(st.order));
    w.attribute("/statistics", "samples", st.samples);
    w.attribute("/statistics", "seed", static_cast<std::int64_t>(st.seed));
    if (!st.covariance.empty()) {  // the file keeps full 3×3 matrices (the body holds 6 values)
      std::vector<double> full(9 * n);
      for (std::size_t k = 0; k < n; ++k) {
        const Eigen::Matrix3d C = st.covariance_of(k);
        for (int a = 0; a < 3; ++a)
          for (int c = 0; c < 3; ++c) full[9 * k + static_cast<std::size_t>(3 * a + c)] = C(a, c);
      }
      w.write("statistics/covariance", full, {n, 3, 3});
    }
    if (!st.frames.empty()) {
      std::vector<double> all;
      all.reserve(st.frames.size() * 3 * n);
      for (const auto& fr : st.frames) all.insert(all.end(), fr.begin(), fr.end());
      w.write("statistics/frames", all, {st.frames.size(), n, 3});
    }
  }
  // homogenisation
  if (b.homogenisation) {
    const auto& hm = *b.homogenisation;
    const std::size_t np = hm.size();
    w.write("homogenisation/points", hm.points, {np, 3});
    w.write("homogenisation/volume", hm.volume);
    w.write("homogenisation/mass", hm.mass);
    std::vector<double> rho(np);
    for (std::size_t p = 0; p < np; ++p)
      rho[p] = hm.volume[p] > 0 ? hm.mass[p] / hm.volume[p] : 0.0;
    w.write("homogenisation/density", rho);
    w.write("homogenisation/offset", hm.offset);
    w.write("homogenisation/atom", to64(hm.atom, 0));
    w.write("homogenisation/weight", hm.weight);
    if (!hm.grid_counts.empty()) {
      w.write("homogenisation/grid_origin", hm.grid_origin);
      w.write("homogenisation/grid_steps", hm.grid_axes, {3, 3});
      w.write("homogenisation/grid_counts", hm.grid_counts);
    }
    w.attribute("/homogenisation", "kernel", hm.kernel);
    w.attribute("/homogenisation", "width", hm.width);
  }
  w.write_strings("provenance", b.provenance.empty() ? std::vector<std::string>{""} : b.provenance);
  w.commit();
}

Body read_body(const std::filesystem::path& path, const PotentialFactory& factory) {
  const io::H5Reader file(path);
  return read_body(file, factory);
}

Body read_body(const io::H5Reader& r, const PotentialFactory& factory) {
  r.require_format("pdcg-body", kBodySchemaVersion);
  const std::string src = r.path().string();
  auto need = [&](std::string_view item) {
    if (!r.exists(item))
      throw InputError("model file lacks a required item")
          .source(src)
          .key(item)
          .expected("a complete pdcg-body file (docs/formats.md)")
          .fix("rewrite it with pdcg atoms2pd");
  };
  Body b;
  b.units = r.info().units;
  b.kind = parse_body_kind(r.attribute_string("/", "kind"), src);
  b.dimension = static_cast<int>(r.attribute_int("/", "dimension"));
  b.epsilon = r.attribute_double("/", "epsilon");
  for (auto item : {"box/lo", "box/hi", "box/tilt", "box/periodic", "points/id", "points/type",
                    "points/x", "points/mass", "families/offset", "families/neighbor",
                    "families/shift", "families/reverse", "families/h", "potential/lines"})
    need(item);
  const auto lo = r.read_double("box/lo"), hi = r.read_double("box/hi"),
             tilt = r.read_double("box/tilt");
  const auto per = r.read_int("box/periodic");
  // fixed-length datasets: a wrong length is refused before any element is read
  auto need_length = [&](const char* key, std::size_t got, std::size_t want) {
    if (got != want)
      throw InputError("dataset of the wrong length")
          .source(src)
          .key(key)
          .value(std::to_string(got) + " values")
          .expected(std::to_string(want) + " values")
          .fix("the file is damaged or not written by pdcg atoms2pd; write it again");
  };
  need_length("box/lo", lo.size(), 3);
  need_length("box/hi", hi.size(), 3);
  need_length("box/tilt", tilt.size(), 3);
  need_length("box/periodic", per.size(), 3);
  b.box.lo = {lo[0], lo[1], lo[2]};
  b.box.hi = {hi[0], hi[1], hi[2]};
  b.box.xy = tilt[0];
  b.box.xz = tilt[1];
  b.box.yz = tilt[2];
  for (int k = 0; k < 3; ++k)
    b.box.periodic[static_cast<std::size_t>(k)] = per[static_cast<std::size_t>(k)] != 0;
  b.id = r.read_int("points/id");
  b.type = narrow<int>(r.read_int("points/type"));
  b.x = r.read_double("points/x");
  b.mass = r.read_double("points/mass");
  const std::size_t n = b.id.size();
  if (b.type.size() != n || b.x.size() != 3 * n || b.mass.size() != n)
    throw InputError("point arrays of different lengths")
        .source(src)
        .key("points")
        .value(fmt::format("{} ids, {} types, {} positions, {} masses", n, b.type.size(),
                           b.x.size() / 3, b.mass.size()))
        .expected("one entry per point");
  auto& f = b.families;
  f.offset = r.read_int("families/offset");
  f.neighbor = narrow<std::int32_t>(r.read_int("families/neighbor"));
  f.shift = narrow_checked<std::int8_t>(r.read_int("families/shift"), src, "families/shift",
                                        "image shifts are held in one byte");
  f.reverse = narrow_checked<std::int32_t>(r.read_int("families/reverse"), src, "families/reverse",
                                           "bond indices are held in 32 bits");
  if (r.exists("families/pair_factor")) f.pair_factor = r.read_double("families/pair_factor");
  if (r.exists("families/bond_type")) f.bond_type = narrow<int>(r.read_int("families/bond_type"));
  const auto hv = r.read_double("families/h");
  need_length("families/h", hv.size(), 9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f.h(i, j) = hv[static_cast<std::size_t>(3 * i + j)];
  b.base_horizon = r.attribute_double("/families", "base_horizon");
  const std::size_t nb = f.neighbor.size();
  if (f.offset.size() != n + 1 || static_cast<std::size_t>(f.offset.back()) != nb ||
      f.shift.size() != 3 * nb || f.reverse.size() != nb)
    throw InputError("families are inconsistent with the points")
        .source(src)
        .key("families")
        .value(fmt::format("{} offsets, {} bonds", f.offset.size(), nb))
        .expected(fmt::format("{} offsets ending at the bond count", n + 1));
  for (std::size_t k = 0; k < nb; ++k)
    if (f.neighbor[k] < 0 || static_cast<std::size_t>(f.neighbor[k]) >= n || f.reverse[k] < 0 ||
        static_cast<std::size_t>(f.reverse[k]) >= nb)
      throw InputError("family bond points outside the body")
          .source(src)
          .key("families/neighbor")
          .value(std::to_string(k));
  // potential spec
  auto& s = b.potential_spec;
  s.lines = r.read_strings("potential/lines");
  if (s.lines.size() == 1 && s.lines[0].empty()) s.lines.clear();
  s.units = b.units;
  s.source = r.attribute_string("/potential", "source");
  s.atom_style = r.attribute_string("/potential", "atom_style");
  // the type count sizes the potential's per-type tables: the bound of atoms2pd, checked
  // before it reaches them (a stored 2^31 − 1 overflowed `ntypes + 1`)
  const std::int64_t ntypes = r.attribute_int("/potential", "ntypes");
  if (ntypes < 1 || ntypes > atomistic::kMaxAtomTypes)
    throw InputError("atom type count of the potential out of range")
        .source(src)
        .key("/potential@ntypes")
        .value(std::to_string(ntypes))
        .expected(fmt::format("1..{} (the atom types of the configuration the body was made from)",
                              atomistic::kMaxAtomTypes))
        .fix("the file is damaged or not written by pdcg atoms2pd; write it again");
  s.ntypes = static_cast<int>(ntypes);
  if (r.exists("potential/type_mass")) s.type_mass = r.read_double("potential/type_mass");
  const auto sl = r.read_double("potential/special_lj"),
             sc = r.read_double("potential/special_coul");
  need_length("potential/special_lj", sl.size(), 3);
  need_length("potential/special_coul", sc.size(), 3);
  for (std::size_t k = 0; k < 3; ++k) {
    s.special_lj[k] = sl[k];
    s.special_coul[k] = sc[k];
  }
  if (r.exists("potential/file_names")) {
    const auto names = r.read_strings("potential/file_names"),
               contents = r.read_strings("potential/file_contents");
    need_length("potential/file_contents", contents.size(), names.size());  // one per name
    for (std::size_t k = 0; k < names.size(); ++k)
      b.potential_files.push_back({names[k], contents[k]});
  }
  // statistics
  if (r.exists("statistics")) {
    Statistics st;
    st.form = r.attribute_string("/statistics", "form") == "gaussian" ? Statistics::Form::gaussian
                                                                      : Statistics::Form::empirical;
    st.method = r.attribute_string("/statistics", "method") == "cubature"
                    ? Statistics::Method::cubature
                    : Statistics::Method::sampling;
    st.order = static_cast<int>(r.attribute_int("/statistics", "order"));
    st.samples = r.attribute_int("/statistics", "samples");
    st.seed = static_cast<std::uint64_t>(r.attribute_int("/statistics", "seed"));
    if (r.exists("statistics/covariance")) {
      const auto full = r.read_double("statistics/covariance");
      if (full.size() != 9 * n)
        throw InputError("covariances do not match the points")
            .source(src)
            .key("statistics/covariance")
            .value(fmt::format("{} values", full.size()))
            .expected(fmt::format("{}×3×3 (one 3×3 matrix per point)", n));
      st.covariance.assign(6 * n, 0.0);
      for (std::size_t k = 0; k < n; ++k) {
        const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> C(full.data() + 9 * k);
        // pdcg writes exactly symmetric matrices (v vᵀ sums); allow round-off of other writers
        if ((C - C.transpose()).cwiseAbs().maxCoeff() > 1e-12 * C.cwiseAbs().maxCoeff())
          throw InputError("covariance is not symmetric")
              .source(src)
              .key(fmt::format("statistics/covariance[{}]", k))
              .expected("Σ_k = Σ_kᵀ")
              .fix("write symmetric covariances");
        st.set_covariance(k, C);
      }
    }
    if (r.exists("statistics/frames")) {
      const auto all = r.read_double("statistics/frames");
      for (std::size_t o = 0; o + 3 * n <= all.size(); o += 3 * n)
        st.frames.emplace_back(all.begin() + static_cast<std::ptrdiff_t>(o),
                               all.begin() + static_cast<std::ptrdiff_t>(o + 3 * n));
    }
    b.statistics = std::move(st);
  }
  if (r.exists("homogenisation")) {
    Homogenisation hm;
    hm.kernel = r.attribute_string("/homogenisation", "kernel");
    hm.width = r.attribute_double("/homogenisation", "width");
    hm.points = r.read_double("homogenisation/points");
    hm.volume = r.read_double("homogenisation/volume");
    hm.mass = r.read_double("homogenisation/mass");
    hm.offset = r.read_int("homogenisation/offset");
    hm.atom = narrow<std::int32_t>(r.read_int("homogenisation/atom"));
    hm.weight = r.read_double("homogenisation/weight");
    if (r.exists("homogenisation/grid_counts")) {
      hm.grid_origin = r.read_double("homogenisation/grid_origin");
      hm.grid_axes = r.read_double("homogenisation/grid_steps");
      hm.grid_counts = r.read_int("homogenisation/grid_counts");
    }
    for (auto a : hm.atom)
      if (a < 0 || static_cast<std::size_t>(a) >= n)
        throw InputError("homogenisation weight names an atom outside the body")
            .source(src)
            .key("homogenisation/atom")
            .value(std::to_string(a));
    b.homogenisation = std::move(hm);
  }
  if (r.exists("provenance")) {
    b.provenance = r.read_strings("provenance");
    if (b.provenance.size() == 1 && b.provenance[0].empty()) b.provenance.clear();
  }
  const PotentialFactory& make = factory ? factory : default_potential_factory();
  if (make) {
    b.base_potential = make(s, b.potential_files);
    b.potential = rescaled_potential(b.base_potential, b.epsilon, b.dimension);
  }
  return b;
}

}  // namespace pdcg::body
