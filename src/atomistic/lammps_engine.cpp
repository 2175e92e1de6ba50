#include "pdcg/atomistic/lammps_engine.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/config.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

#if PDCG_WITH_LAMMPS
#include <library.h>
#endif

#ifdef _OPENMP
#include <omp.h>
#endif

extern char** environ;

namespace pdcg::atomistic {

struct LammpsEngine::Impl {
  PotentialSpec spec;
  mutable std::vector<std::string> commands;
};

#if PDCG_WITH_LAMMPS  // helpers used only when LAMMPS is embedded
namespace {

std::string g17(double v) { return fmt::format("{:.17g}", v); }

enum class AtomLine { atomic, charge, bond, full };

AtomLine atom_line_of(const PotentialSpec& spec) {
  const std::string& s = spec.atom_style;
  if (s == "atomic") return AtomLine::atomic;
  if (s == "charge") return AtomLine::charge;
  if (s == "bond" || s == "angle" || s == "molecular") return AtomLine::bond;
  if (s == "full") return AtomLine::full;
  throw InputError("atom_style not supported by the embedded LAMMPS driver")
      .source(spec.source)
      .key("atom_style")
      .value(s)
      .expected("atomic, charge, bond, angle, molecular or full");
}

/// The potential commands rebuilt from the spec, with potential files resolved, and the line
/// of spec.source each comes from.
std::vector<LammpsCommand> potential_commands(const PotentialSpec& spec) {
  std::vector<LammpsCommand> cmds;
  for (int t = 1; t < static_cast<int>(spec.type_mass.size()); ++t)
    if (!std::isnan(spec.type_mass[static_cast<std::size_t>(t)]))
      cmds.push_back(
          {fmt::format("mass {} {}", t, g17(spec.type_mass[static_cast<std::size_t>(t)])), 0});
  // words appended with std::string::append (GCC 12 reports a false -Wrestrict for " " + s)
  auto command = [](std::string_view head,
                    std::initializer_list<const std::vector<std::string>*> parts) {
    std::string out(head);
    for (const auto* words : parts)
      for (const auto& w : *words) out.append(1, ' ').append(w);
    return out;
  };
  if (!spec.pair_style.empty()) {
    const std::vector<std::string> style{spec.pair_style};
    cmds.push_back({command("pair_style", {&style, &spec.pair_style_args}), spec.pair_style_line});
    for (const auto& c : spec.pair_coeff) {
      std::vector<std::string> args = c.args;
      const std::string file = coeff_file_argument(spec, c);
      if (!file.empty())
        for (auto& a : args)
          if (a == file) {
            a = find_potential_file(file).value_or(file);
            break;
          }
      const std::vector<std::string> types{c.i, c.j};
      cmds.push_back({command("pair_coeff", {&types, &args}), c.line_number});
    }
    if (!spec.pair_modify.empty())
      cmds.push_back({command("pair_modify", {&spec.pair_modify}), spec.pair_style_line});
  }
  if (!spec.bond_style.empty()) {
    const std::vector<std::string> style{spec.bond_style};
    cmds.push_back({command("bond_style", {&style, &spec.bond_style_args}), spec.bond_style_line});
    for (const auto& c : spec.bond_coeff) {
      const std::vector<std::string> type{c.i};
      cmds.push_back({command("bond_coeff", {&type, &c.args}), c.line_number});
    }
  }
  if (!spec.bond_style.empty())
    cmds.push_back(
        {fmt::format("special_bonds lj {} {} {} coul {} {} {}", g17(spec.special_lj[0]),
                     g17(spec.special_lj[1]), g17(spec.special_lj[2]), g17(spec.special_coul[0]),
                     g17(spec.special_coul[1]), g17(spec.special_coul[2])),
         0});
  return cmds;
}

/// The `lmp` executable: $PDCG_LMP, else `lmp` on PATH; empty if none.
std::string lmp_executable() {
  if (const char* e = std::getenv("PDCG_LMP"); e && *e) return e;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::string p = dir + "/lmp";
    if (access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

/// A new liblammps instance with no log, screen or citation output. liblammps sets the OpenMP
/// thread count of the process; the caller's is restored.
void* open_quiet_lammps() {
#ifdef _OPENMP
  const int threads = omp_get_max_threads();
#endif
  const char* args[] = {"pdcg", "-log", "none", "-screen", "none", "-nocite"};
  void* lmp = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
#ifdef _OPENMP
  omp_set_num_threads(threads);
#endif
  if (!lmp) throw InputError("liblammps failed to start").fix("check the LAMMPS installation");
  return lmp;
}

}  // namespace
#endif

#if PDCG_WITH_LAMMPS
std::vector<std::string> lammps_potential_commands(const PotentialSpec& spec) {
  std::vector<std::string> out;
  for (auto& c : potential_commands(spec)) out.push_back(std::move(c.text));
  return out;
}

std::vector<LammpsCommand> lammps_potential_command_lines(const PotentialSpec& spec) {
  return potential_commands(spec);
}

bool check_lammps_commands(const std::vector<LammpsCommand>& commands, const PotentialSpec& spec,
                           std::string_view context) {
  static std::mutex mutex;  // the warning set and the one-time notice
  static std::set<std::string> warned;
  const std::string lmp = lmp_executable();
  if (lmp.empty()) {
    std::lock_guard<std::mutex> lock(mutex);
    static bool told = false;
    if (!told)
      log::warn(
          "no `lmp` executable on PATH (or $PDCG_LMP): LAMMPS errors in embedded LAMMPS cannot "
          "be reported; such an error stops pdcg with exit code 1 and no message");
    told = true;
    return false;
  }
  std::string dir_tmpl = (std::filesystem::temp_directory_path() / "pdcg_lmpcheck_XXXXXX").string();
  if (!mkdtemp(dir_tmpl.data()))
    throw InputError("cannot create a temporary directory for LAMMPS")
        .value(dir_tmpl)
        .fix("check TMPDIR");
  const std::filesystem::path dir(dir_tmpl);
  struct RemoveDir {
    std::filesystem::path p;
    ~RemoveDir() {
      std::error_code ec;
      std::filesystem::remove_all(p, ec);
    }
  } remove_dir{dir};
  const std::string in = (dir / "in.pdcg").string(), logf = (dir / "log.lammps").string(),
                    out = (dir / "out.txt").string();
  {
    std::ofstream f(in);
    for (const auto& c : commands) f << c.text << '\n';
    if (!f) throw InputError("cannot write a temporary LAMMPS input").value(in);
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<std::string> argv_s{lmp, "-in", in, "-log", logf, "-screen", "none", "-nocite"};
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  // one OpenMP thread in the child (LAMMPS otherwise prints a notice; no effect on results)
  std::vector<std::string> env_s{"OMP_NUM_THREADS=1"};
  for (char** e = environ; e && *e; ++e)
    if (std::string_view(*e).rfind("OMP_NUM_THREADS=", 0) != 0) env_s.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, lmp.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw InputError("cannot start the LAMMPS executable that checks the commands")
        .value(lmp)
        .fix("check the LAMMPS installation, or set PDCG_LMP to its `lmp` executable");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) break;
  // LAMMPS's log: ERROR lines, the failing command, WARNING lines
  std::string error, last;
  std::vector<std::string> warnings;
  {
    std::ifstream f(logf);
    std::string l;
    while (std::getline(f, l)) {
      if (l.rfind("ERROR", 0) == 0) {
        const auto colon = l.find(": ");
        if (error.empty()) error = trim(colon == std::string::npos ? l : l.substr(colon + 2));
      } else if (l.rfind("Last command:", 0) == 0) {
        last = trim(l.substr(13));
      } else if (l.rfind("WARNING: ", 0) == 0 && l.find("No fixes defined") == std::string::npos) {
        // (pdcg's own `run 0` has no fixes by design: that warning is not the user's)
        warnings.push_back(trim(l.substr(9)));
      }
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& w : warnings)
      if (warned.insert(w).second) log::warn("LAMMPS ({}): {}", spec.source, w);
  }
  const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (ok && error.empty()) return true;
  std::string output;
  {
    std::ifstream f(out);
    std::string l;
    while (std::getline(f, l))
      if (!trim(l).empty() && output.size() < 2000)
        output += (output.empty() ? "" : " | ") + trim(l);
  }
  if (error.empty())
    error = WIFSIGNALED(status)
                ? fmt::format("LAMMPS crashed (signal {}){}", WTERMSIG(status),
                              output.empty() ? "" : ": " + output)
                : fmt::format("LAMMPS stopped with exit status {} and no ERROR line{}",
                              WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                              output.empty() ? "" : ": " + output);
  // the failing command: LAMMPS's "Last command", else the last command the log echoes
  long line = 0;
  std::string failed = last;
  for (const auto& c : commands)
    if (!last.empty() && trim(c.text) == last) {
      line = c.line;
      failed = c.text;
    }
  std::string key = failed.substr(0, failed.find(' '));
  if (line == 0) {
    // pdcg's own command (read_data, run 0, …): the error is about the model as a whole
    line = spec.pair_style_line ? spec.pair_style_line : spec.bond_style_line;
    key = spec.pair_style.empty() ? "bond_style" : "pair_style";
  }
  InputError e(fmt::format("LAMMPS error while {}", context));
  e.source(spec.source).line(line).key(key).value(error);
  if (!failed.empty())
    e.expected(fmt::format("a model LAMMPS accepts (failing command: {})", failed));
  e.fix("correct the command LAMMPS names (https://docs.lammps.org/Errors_messages.html)");
  throw e;
}
#endif

void require_engine_representable(const PotentialSpec& spec) {
  std::vector<std::string> styles{spec.pair_style};
  if (spec.pair_style.rfind("hybrid", 0) == 0)
    styles.insert(styles.end(), spec.pair_style_args.begin(), spec.pair_style_args.end());
  for (const auto& st : styles)
    if (st.find("/long") != std::string::npos || st.find("/msm") != std::string::npos ||
        st.find("/pppm") != std::string::npos)
      throw InputError(
          "long-range (k-space) pair style: its reciprocal-space energy is not a sum over "
          "finite families, so pdcg cannot represent it")
          .source(spec.source)
          .line(spec.pair_style_line)
          .key("pair_style")
          .value(st)
          .expected("a pair style with a finite cutoff and no kspace_style")
          .fix(
              "use the cut-off form (lj/cut/coul/cut, buck/coul/cut, lj/cut/coul/dsf, "
              "coul/wolf, …), or compute this model with LAMMPS itself");
}

void take_type_charges(PotentialSpec& spec, const Atoms& atoms) {
  if ((spec.atom_style != "charge" && spec.atom_style != "full") || atoms.charge.empty()) return;
  const int nt = std::max(spec.ntypes, 1);
  std::vector<double> q(static_cast<std::size_t>(nt) + 1, std::nan(""));
  std::vector<std::int64_t> first(q.size(), 0);
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    const int t = atoms.type.empty() ? 1 : atoms.type[i];
    if (t < 1 || t > nt) continue;  // reported by the type checks of the body
    auto& qt = q[static_cast<std::size_t>(t)];
    if (std::isnan(qt)) {
      qt = atoms.charge[i];
      first[static_cast<std::size_t>(t)] = atoms.id.empty() ? 0 : atoms.id[i];
    } else if (atoms.charge[i] != qt)
      throw InputError(
          "atoms of one type carry different charges: the embedded-LAMMPS force states carry "
          "one charge per atom type")
          .key("charge")
          .value(fmt::format("type {}: atom {} has q = {}, atom {} has q = {}", t,
                             first[static_cast<std::size_t>(t)], fmt::format("{:.17g}", qt),
                             atoms.id.empty() ? 0 : atoms.id[i],
                             fmt::format("{:.17g}", atoms.charge[i])))
          .expected("the same charge for every atom of a type")
          .fix("give each charge its own atom type in the data file");
  }
  for (int t = 1; t <= nt; ++t) {
    const auto k = static_cast<std::size_t>(t);
    const double set = k < spec.type_charge.size() ? spec.type_charge[k] : std::nan("");
    if (!std::isnan(set) && !std::isnan(q[k]) && set != q[k])
      throw InputError("the potential commands and the configuration disagree on a charge")
          .source(spec.source)
          .key("set type charge")
          .value(fmt::format("type {}: set type charge {}, data file {}", t,
                             fmt::format("{:.17g}", set), fmt::format("{:.17g}", q[k])))
          .expected("the same charge")
          .fix("drop the `set type` line or correct the data file");
  }
  if (spec.type_charge.size() < q.size()) spec.type_charge.resize(q.size(), std::nan(""));
  for (int t = 1; t <= nt; ++t) {
    const auto k = static_cast<std::size_t>(t);
    if (std::isnan(spec.type_charge[k]) && !std::isnan(q[k])) {
      spec.type_charge[k] = q[k];
      spec.lines.push_back(fmt::format("set type {} charge {}", t, fmt::format("{:.17g}", q[k])));
    }
  }
}

LammpsEngine::LammpsEngine(PotentialSpec spec) : impl_(std::make_unique<Impl>()) {
  require_supported_styles(spec);
  require_engine_representable(spec);
#if !PDCG_WITH_LAMMPS
  throw InputError("embedded LAMMPS is not available in this build")
      .source(spec.source)
      .key("pair_style")
      .value(spec.pair_style)
      .fix("rebuild pdcg with -DPDCG_ENABLE_LAMMPS=ON");
#else
  const AtomLine line_style = atom_line_of(spec);
  if (!spec.bond_style.empty() && line_style != AtomLine::bond && line_style != AtomLine::full)
    throw InputError("bond_style needs an atom style with bonds")
        .source(spec.source)
        .line(spec.bond_style_line)
        .key("atom_style")
        .value(spec.atom_style)
        .expected("atom_style bond, angle, molecular or full")
        .fix("add 'atom_style bond' (or the style of the data file) to the potential commands");
  for (const auto& c : spec.pair_coeff) {
    const std::string file = coeff_file_argument(spec, c);
    if (!file.empty() && !find_potential_file(file))
      throw InputError("potential file not found")
          .source(spec.source)
          .line(c.line_number)
          .key("pair_coeff")
          .value(file)
          .expected(
              std::string(
                  "a readable file: the path as given, or its name in $LAMMPS_POTENTIALS or ") +
              PDCG_LAMMPS_POTENTIALS_DIR);
  }
  // Native styles: validate coefficients with pdcg's own checks first (LAMMPS would abort).
  const bool native_pair = spec.pair_style.empty() || native_pair_style(spec.pair_style);
  const bool native_bond = spec.bond_style.empty() || native_bond_style(spec.bond_style);
  if (native_pair && native_bond && spec.ntypes > 0) (void)make_potential(spec);
  // Styles this liblammps knows (checked on a throw-away instance).
  {
    void* lmp = open_quiet_lammps();
    auto missing = [&](const char* category, const std::string& style) {
      return !style.empty() && !lammps_has_style(lmp, category, style.c_str());
    };
    std::string bad_pair;
    if (missing("pair", spec.pair_style)) bad_pair = spec.pair_style;
    if (spec.pair_style.rfind("hybrid", 0) == 0)
      for (const auto& a : spec.pair_style_args)
        if (!a.empty() && !std::isdigit(static_cast<unsigned char>(a[0])) && a != "scale" &&
            missing("pair", a)) {
          // hybrid arguments are sub-style names and their numeric settings
          bad_pair = a;
        }
    const bool bad_bond = missing("bond", spec.bond_style);
    lammps_close(lmp);
    if (!bad_pair.empty())
      throw InputError("pair style unknown to the embedded LAMMPS")
          .source(spec.source)
          .line(spec.pair_style_line)
          .key("pair_style")
          .value(bad_pair)
          .expected("a style of this LAMMPS build (lmp -h lists them)")
          .fix("check the spelling, or use a LAMMPS built with the package providing it");
    if (bad_bond)
      throw InputError("bond style unknown to the embedded LAMMPS")
          .source(spec.source)
          .line(spec.bond_style_line)
          .key("bond_style")
          .value(spec.bond_style)
          .expected("a style of this LAMMPS build (lmp -h lists them)");
  }
  impl_->spec = std::move(spec);
#endif
}

LammpsEngine::~LammpsEngine() = default;
LammpsEngine::LammpsEngine(LammpsEngine&&) noexcept = default;
LammpsEngine& LammpsEngine::operator=(LammpsEngine&&) noexcept = default;

const std::vector<std::string>& LammpsEngine::commands() const { return impl_->commands; }

LammpsResult LammpsEngine::evaluate(const Atoms& atoms) const {
  return energy_derivatives(atoms, 0.0, {});
}

LammpsResult LammpsEngine::energy_derivatives(const Atoms& atoms, double step,
                                              const DerivativeSink& sink) const {
#if !PDCG_WITH_LAMMPS
  (void)atoms;
  (void)step;
  (void)sink;
  throw InputError("embedded LAMMPS is not available in this build")
      .fix("rebuild pdcg with -DPDCG_ENABLE_LAMMPS=ON");
#else
  const PotentialSpec& spec = impl_->spec;
  const std::size_t n = atoms.size();
  const AtomLine style = atom_line_of(spec);
  int ntypes = spec.ntypes;
  for (std::size_t i = 0; i < n; ++i) {
    const int t = atoms.type.empty() ? 1 : atoms.type[i];
    if (t < 1 || (spec.ntypes > 0 && t > spec.ntypes))
      throw InputError("atom type outside the potential's types")
          .key("type")
          .value(std::to_string(t))
          .expected("1.." + std::to_string(spec.ntypes))
          .fix("the configuration and the potential file disagree on the atom types");
    ntypes = std::max(ntypes, t);
  }
  const bool molecular = style == AtomLine::bond || style == AtomLine::full;
  int nbondtypes = 0;
  if (molecular) {
    for (const auto& b : atoms.bonds) nbondtypes = std::max(nbondtypes, b.type);
    for (const auto& c : spec.bond_coeff)
      if (!c.i.empty() && std::isdigit(static_cast<unsigned char>(c.i[0])))
        nbondtypes = std::max(nbondtypes, std::atoi(c.i.c_str()));
  }

  // Box: non-periodic directions widened to hold every atom (orthogonal boxes).
  Box box = atoms.box;
  const bool nonperiodic = !box.periodic[0] || !box.periodic[1] || !box.periodic[2];
  if (nonperiodic && n > 0) {
    Eigen::Vector3d lo = atoms.positions().rowwise().minCoeff(),
                    hi = atoms.positions().rowwise().maxCoeff();
    const double margin =
        std::max(0.05 * (hi - lo).maxCoeff(), 1e-3 * std::max(1.0, box.lengths().maxCoeff()));
    if (box.triclinic()) {
      for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d s =
            box.to_fractional({atoms.x[3 * i], atoms.x[3 * i + 1], atoms.x[3 * i + 2]});
        for (int k = 0; k < 3; ++k)
          if (!box.periodic[static_cast<std::size_t>(k)] && (s[k] < 0.0 || s[k] >= 1.0))
            throw InputError("atom outside a non-periodic direction of a triclinic box")
                .key("box")
                .expected("atoms inside the box along non-periodic directions")
                .fix("enlarge the box along the non-periodic direction");
      }
    } else {
      for (int k = 0; k < 3; ++k)
        if (!box.periodic[static_cast<std::size_t>(k)]) {
          box.lo[k] = std::min(box.lo[k], lo[k] - margin);
          box.hi[k] = std::max(box.hi[k], hi[k] + margin);
        }
    }
  }

  // Molecular bonds: LAMMPS aborts on a FENE bond longer than 2 R0 and on bond partners
  // beyond the ghost cutoff; check the first and widen the second (comm_modify cutoff).
  double longest_bond = 0.0;
  if (molecular && !atoms.bonds.empty()) {
    std::vector<std::pair<std::int64_t, std::size_t> > id_index(n);
    for (std::size_t i = 0; i < n; ++i) id_index[i] = {atoms.id[i], i};
    std::sort(id_index.begin(), id_index.end());
    auto index_of = [&](std::int64_t id) {
      auto it =
          std::lower_bound(id_index.begin(), id_index.end(), std::make_pair(id, std::size_t{0}));
      if (it == id_index.end() || it->first != id)
        throw InputError("bond names an atom id that is not in the configuration")
            .key("Bonds")
            .value(std::to_string(id));
      return it->second;
    };
    for (const auto& b : atoms.bonds) {
      const std::size_t i = index_of(b.atom1), j = index_of(b.atom2);
      const Eigen::Vector3d d = box.minimum_image_exact(
          Eigen::Vector3d(atoms.x[3 * j] - atoms.x[3 * i], atoms.x[3 * j + 1] - atoms.x[3 * i + 1],
                          atoms.x[3 * j + 2] - atoms.x[3 * i + 2]));
      const double r = d.norm();
      longest_bond = std::max(longest_bond, r);
      if (spec.bond_style == "fene")
        for (const auto& c : spec.bond_coeff) {
          if (c.args.size() < 2 || c.i != std::to_string(b.type)) continue;
          const double r0 = std::atof(c.args[1].c_str());
          if (r * r >= 4.0 * r0 * r0)
            throw InputError("FENE bond longer than 2 R0: LAMMPS would stop ('Bad FENE bond')")
                .source(spec.source)
                .line(c.line_number)
                .key("bond_coeff")
                .value(fmt::format("bond {}-{} of length {:.6g}", b.atom1, b.atom2, r))
                .expected(fmt::format("bonds shorter than 2 R0 = {:.6g}", 2 * r0));
        }
    }
  }

  // Temporary data file.
  std::string tmpl = (std::filesystem::temp_directory_path() / "pdcg_lammps_XXXXXX").string();
  const int fd = mkstemp(tmpl.data());
  if (fd < 0)
    throw InputError("cannot create a temporary file for LAMMPS").value(tmpl).fix("check TMPDIR");
  close(fd);
  struct Remove {
    std::string p;
    ~Remove() { std::remove(p.c_str()); }
  } remove_tmp{tmpl};
  {
    std::ofstream out(tmpl);
    out << "pdcg configuration for embedded LAMMPS\n\n"
        << n << " atoms\n"
        << ntypes << " atom types\n";
    if (molecular && nbondtypes > 0)
      out << atoms.bonds.size() << " bonds\n" << nbondtypes << " bond types\n";
    out << g17(box.lo[0]) << ' ' << g17(box.hi[0]) << " xlo xhi\n"
        << g17(box.lo[1]) << ' ' << g17(box.hi[1]) << " ylo yhi\n"
        << g17(box.lo[2]) << ' ' << g17(box.hi[2]) << " zlo zhi\n";
    if (box.triclinic())
      out << g17(box.xy) << ' ' << g17(box.xz) << ' ' << g17(box.yz) << " xy xz yz\n";
    out << "\nMasses\n\n";
    for (int t = 1; t <= ntypes; ++t) {
      double m = std::nan("");
      if (static_cast<std::size_t>(t) < atoms.type_mass.size())
        m = atoms.type_mass[static_cast<std::size_t>(t)];
      if (std::isnan(m) && static_cast<std::size_t>(t) < spec.type_mass.size())
        m = spec.type_mass[static_cast<std::size_t>(t)];
      if (std::isnan(m)) m = 1.0;  // masses do not enter energies or forces
      out << t << ' ' << g17(m) << '\n';
    }
    out << "\nAtoms\n\n";
    for (std::size_t i = 0; i < n; ++i) {
      const int t = atoms.type.empty() ? 1 : atoms.type[i];
      const long long mol = atoms.molecule.empty() ? 1 : static_cast<long long>(atoms.molecule[i]);
      double q = atoms.charge.empty() ? 0.0 : atoms.charge[i];
      if (atoms.charge.empty() && static_cast<std::size_t>(t) < spec.type_charge.size() &&
          !std::isnan(spec.type_charge[static_cast<std::size_t>(t)]))
        q = spec.type_charge[static_cast<std::size_t>(t)];  // `set type T charge Q`
      out << (i + 1) << ' ';
      if (style == AtomLine::bond || style == AtomLine::full) out << mol << ' ';
      out << t << ' ';
      if (style == AtomLine::charge || style == AtomLine::full) out << g17(q) << ' ';
      out << g17(atoms.x[3 * i]) << ' ' << g17(atoms.x[3 * i + 1]) << ' ' << g17(atoms.x[3 * i + 2])
          << '\n';
    }
    if (molecular && nbondtypes > 0 && !atoms.bonds.empty()) {
      // atom ids → 1-based index in the file
      std::vector<std::pair<std::int64_t, std::int64_t> > id_index(n);
      for (std::size_t i = 0; i < n; ++i)
        id_index[i] = {atoms.id[i], static_cast<std::int64_t>(i + 1)};
      std::sort(id_index.begin(), id_index.end());
      auto index_of = [&](std::int64_t id) {
        auto it =
            std::lower_bound(id_index.begin(), id_index.end(), std::make_pair(id, std::int64_t{0}));
        if (it == id_index.end() || it->first != id)
          throw InputError("bond names an atom id that is not in the configuration")
              .key("Bonds")
              .value(std::to_string(id));
        return it->second;
      };
      out << "\nBonds\n\n";
      std::size_t k = 0;
      for (const auto& b : atoms.bonds)
        out << ++k << ' ' << b.type << ' ' << index_of(b.atom1) << ' ' << index_of(b.atom2) << '\n';
    }
    if (!out) throw InputError("cannot write the temporary LAMMPS data file").value(tmpl);
  }

  std::vector<LammpsCommand> script{
      {"units " + std::string(to_string(spec.units)), spec.units_line},
      {"atom_style " + spec.atom_style, 0},
      {"atom_modify map array sort 0 0.0", 0},
      {fmt::format("boundary {} {} {}", box.periodic[0] ? 'p' : 'f', box.periodic[1] ? 'p' : 'f',
                   box.periodic[2] ? 'p' : 'f'),
       0}};
  if (box.triclinic()) script.push_back({"box tilt large", 0});
  script.push_back({"read_data " + tmpl, 0});
  for (auto& c : potential_commands(spec)) script.push_back(std::move(c));
  if (longest_bond > 0.0)
    script.push_back({fmt::format("comm_modify cutoff {}", g17(1.5 * longest_bond)), 0});
  for (const char* c :
       {"compute pdcg_pe all pe/atom", "compute pdcg_pesum all reduce sum c_pdcg_pe",
        "thermo_style custom step pe c_pdcg_pesum", "thermo_modify norm no", "run 0 post no"})
    script.push_back({c, 0});
  std::vector<std::string>& cmds = impl_->commands;
  cmds.clear();
  for (const auto& c : script) cmds.push_back(c.text);
  // LAMMPS errors stop the process inside liblammps: run the script in `lmp` first
  check_lammps_commands(script, spec, "evaluating the configuration");

  void* lmp = open_quiet_lammps();
  struct Close {
    void* h;
    ~Close() { lammps_close(h); }
  } closer{lmp};
  for (const auto& c : cmds) lammps_command(lmp, c.c_str());

  const int nlocal = lammps_extract_setting(lmp, "nlocal");
  if (nlocal != static_cast<int>(n))
    throw InputError("LAMMPS lost atoms")
        .value(std::to_string(nlocal) + " of " + std::to_string(n))
        .fix("check the box and periodicity");
  const int tagsize = lammps_extract_setting(lmp, "tagint");
  void* tag = lammps_extract_atom(lmp, "id");
  auto** f = static_cast<double**>(lammps_extract_atom(lmp, "f"));
  auto* pe =
      static_cast<double*>(lammps_extract_compute(lmp, "pdcg_pe", LMP_STYLE_ATOM, LMP_TYPE_VECTOR));
  LammpsResult r;
  r.energy.assign(n, 0.0);
  r.force.assign(3 * n, 0.0);
  for (int i = 0; i < nlocal; ++i) {
    const std::int64_t id =
        tagsize == 8 ? static_cast<std::int64_t*>(tag)[i] : static_cast<std::int32_t*>(tag)[i];
    const auto k = static_cast<std::size_t>(id - 1);
    r.energy[k] = pe[i];
    for (int d = 0; d < 3; ++d) r.force[3 * k + static_cast<std::size_t>(d)] = f[i][d];
  }
  for (double e : r.energy) r.total_energy += e;
  if (!sink) return r;
  if (!(step > 0.0) || !std::isfinite(step))
    throw InputError("finite-difference step must be positive")
        .key("step")
        .value(g17(step))
        .expected("a small positive length, e.g. 1e-5 of the bond length");

  // Central differences. Positions are changed in place through the atom map (sort is off,
  // serial: local order never changes, but the map is re-read after every run to be safe);
  // LAMMPS may wrap a moved atom across a periodic boundary, which leaves energies unchanged,
  // so the position is restored by adding back the same offsets.
  std::vector<double> plus(n), dpsi(n);
  auto read_energies = [&](std::vector<double>& out) {
    const int nl = lammps_extract_setting(lmp, "nlocal");
    if (nl != static_cast<int>(n))
      throw NumericalError(
          fmt::format("LAMMPS lost atoms during finite differences: {} of {} "
                      "left; the step {} moved an atom out of a non-periodic box",
                      nl, n, g17(step)));
    void* tg = lammps_extract_atom(lmp, "id");
    auto* e = static_cast<double*>(
        lammps_extract_compute(lmp, "pdcg_pe", LMP_STYLE_ATOM, LMP_TYPE_VECTOR));
    for (int i = 0; i < nl; ++i) {
      const std::int64_t id =
          tagsize == 8 ? static_cast<std::int64_t*>(tg)[i] : static_cast<std::int32_t*>(tg)[i];
      out[static_cast<std::size_t>(id - 1)] = e[i];
    }
  };
  auto move = [&](std::size_t k, int d, double delta) {
    const int nl = lammps_extract_setting(lmp, "nlocal");
    void* tg = lammps_extract_atom(lmp, "id");
    auto** x = static_cast<double**>(lammps_extract_atom(lmp, "x"));
    for (int i = 0; i < nl; ++i) {
      const std::int64_t id =
          tagsize == 8 ? static_cast<std::int64_t*>(tg)[i] : static_cast<std::int32_t*>(tg)[i];
      if (static_cast<std::size_t>(id - 1) == k) {
        x[i][d] += delta;
        return;
      }
    }
  };
  for (std::size_t j = 0; j < n; ++j)
    for (int d = 0; d < 3; ++d) {
      move(j, d, step);
      lammps_command(lmp, "run 0 post no");
      read_energies(plus);
      move(j, d, -2.0 * step);
      lammps_command(lmp, "run 0 post no");
      read_energies(dpsi);
      move(j, d, step);
      for (std::size_t k = 0; k < n; ++k) dpsi[k] = (plus[k] - dpsi[k]) / (2.0 * step);
      sink(j, d, std::span<const double>(dpsi));
    }
  return r;
#endif
}

double lammps_force_states(const LammpsEngine& engine, const Atoms& atoms, const Families& families,
                           std::span<double> psi_out, std::span<double> t_out, double step) {
  const std::size_t n = atoms.size();
  if (families.points() != n)
    throw InputError("families and configuration differ in size")
        .value(fmt::format("{} family points, {} atoms", families.points(), n))
        .expected("the configuration the families were built from");
  if (psi_out.size() != n || t_out.size() != 3 * families.bonds())
    throw InputError("lammps_force_states: output arrays of the wrong size")
        .expected(
            fmt::format("{} energies and {} force-state components", n, 3 * families.bonds()));
  // (1) one image per atom in every family (families are sorted by neighbour, then shift).
  for (std::size_t k = 0; k < n; ++k)
    for (auto b = families.offset[k] + 1; b < families.offset[k + 1]; ++b)
      if (families.neighbor[static_cast<std::size_t>(b)] ==
          families.neighbor[static_cast<std::size_t>(b - 1)])
        throw InputError(
            "a family holds two periodic images of one atom: finite differences of LAMMPS "
            "energies cannot separate them")
            .key("box")
            .value(fmt::format(
                "atom id {} sees atom id {} twice", atoms.id[k],
                atoms.id[static_cast<std::size_t>(families.neighbor[static_cast<std::size_t>(b)])]))
            .expected("periodic box edges longer than twice the horizon")
            .fix("replicate the configuration (LAMMPS `replicate`) before building the body");
  if (step == 0.0 && families.bonds() > 0) {
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k)
      for (auto b = static_cast<std::size_t>(families.offset[k]);
           b < static_cast<std::size_t>(families.offset[k + 1]); ++b)
        sum += bond_vector(families, atoms.x, k, b).norm();
    step = 1e-5 * sum / static_cast<double>(families.bonds());  // O(h²) ≈ 1e-10 relative
  }
  if (step == 0.0) step = 1e-5;
  std::fill(t_out.begin(), t_out.end(), 0.0);
  std::vector<char> covered(n, 0);
  double largest = 0.0, worst_outside = 0.0;
  std::size_t worst_k = 0, worst_j = 0;
  const LammpsResult r = engine.energy_derivatives(
      atoms, step, [&](std::size_t j, int d, std::span<const double> dpsi) {
        std::fill(covered.begin(), covered.end(), 0);
        covered[j] = 1;  // ∂ψ_j/∂y_j = −Σ_k ∂ψ_j/∂y_k (translation invariance): not a bond
        for (auto b = families.offset[j]; b < families.offset[j + 1]; ++b) {
          const auto k = static_cast<std::size_t>(families.neighbor[static_cast<std::size_t>(b)]);
          const auto rb = static_cast<std::size_t>(families.reverse[static_cast<std::size_t>(b)]);
          t_out[3 * rb + static_cast<std::size_t>(d)] = dpsi[k];  // bond k → j
          covered[k] = 1;
        }
        for (std::size_t k = 0; k < n; ++k) {
          largest = std::max(largest, std::abs(dpsi[k]));
          if (!covered[k] && std::abs(dpsi[k]) > worst_outside) {
            worst_outside = std::abs(dpsi[k]);
            worst_k = k;
            worst_j = j;
          }
        }
      });
  // (2) ψ_k must not depend on atoms outside k's family. 1e-7: far above the finite-difference
  // noise (≈ 1e-16 |ψ|/h), far below a real interaction.
  if (worst_outside > 1e-7 * largest) {
    const Eigen::Vector3d d = atoms.box.minimum_image_exact(
        Eigen::Vector3d(atoms.x[3 * worst_j] - atoms.x[3 * worst_k],
                        atoms.x[3 * worst_j + 1] - atoms.x[3 * worst_k + 1],
                        atoms.x[3 * worst_j + 2] - atoms.x[3 * worst_k + 2]));
    throw InputError(
        "horizon too small for this potential: an atom's energy depends on an atom "
        "outside its family")
        .key("cutoff")
        .value(fmt::format("ψ of atom id {} depends on atom id {} at distance {:.6g} "
                           "(|∂ψ/∂y| = {:.3g}, largest {:.3g})",
                           atoms.id[worst_k], atoms.id[worst_j], d.norm(), worst_outside, largest))
        .expected("families that hold every atom a per-atom energy depends on")
        .fix(
            "build the body with cutoff ≥ 2 r_c for three-body and bond-order styles "
            "(sw, tersoff)");
  }
  std::copy(r.energy.begin(), r.energy.end(), psi_out.begin());
  return r.total_energy;
}

}  // namespace pdcg::atomistic
