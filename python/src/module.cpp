// The compiled part of the Python module `pdcg` (docs/python.md): pdcg's library types and
// functions as `pdcg._pdcg`. The Python package (python/pdcg/__init__.py) builds the public API
// on top of it (from_lammps, from_ase, run with dict scenes).
//
// Ownership: every object Python sees holds its data through a std::shared_ptr, and every numpy
// array that views library memory (no copy) keeps that shared_ptr alive through its base
// capsule, so an array or a body outlives the objects it came from. Long calls release the GIL.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "pdcg/atomistic/configurations.hpp"
#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/body/build.hpp"
#include "pdcg/body/cauchy_born.hpp"
#include "pdcg/body/lattice.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/coarsen/homogenise.hpp"
#include "pdcg/coarsen/kernels.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/progress.hpp"
#include "pdcg/core/units.hpp"
#include "pdcg/core/version.hpp"
#include "pdcg/dispersion/body_dispersion.hpp"
#include "pdcg/dispersion/model.hpp"
#include "pdcg/dispersion/plan.hpp"
#include "pdcg/scene/scene.hpp"

namespace py = pybind11;
using namespace pdcg;

namespace {

// ---- numpy views of library memory -------------------------------------------------------

/// A read-only numpy array over `data` (no copy) whose base keeps `owner` alive.
template <class T, class Owner>
py::array view(const std::shared_ptr<Owner>& owner, const T* data, std::vector<py::ssize_t> shape) {
  auto* keep = new std::shared_ptr<Owner>(owner);
  py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<Owner>*>(p); });
  py::array_t<T> a(shape, data, base);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

/// A numpy array owning a copy of v (results of one evaluation: the evaluator reuses its work
/// arrays, so they cannot be views).
template <class T>
py::array_t<T> copy_of(std::span<const T> v, std::vector<py::ssize_t> shape) {
  py::array_t<T> a(shape);
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<double> matrix(const Eigen::MatrixXd& m) {
  py::array_t<double> a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto r = a.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) r(i, j) = m(i, j);
  return a;
}

/// A C-contiguous double array of shape (n, 3) (any n ≥ 0); InputError naming `what` otherwise.
py::array_t<double, py::array::c_style | py::array::forcecast> rows3(const py::handle& h,
                                                                     std::string_view what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 2 || a.shape(1) != 3)
    throw InputError("wrong array shape")
        .key(what)
        .value(a ? fmt::format("{} dimensions", a.ndim()) : std::string("not a number array"))
        .expected("an (N, 3) array of numbers");
  return a;
}

Eigen::Matrix3d mat3(const py::handle& h, std::string_view what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
    throw InputError("wrong array shape").key(what).expected("a 3×3 matrix");
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = a.at(i, j);
  return m;
}

// ---- Atoms --------------------------------------------------------------------------------

/// One configuration plus where it came from (what the CLI knows from the file name).
struct AtomsHandle {
  atomistic::Atoms atoms;
  std::string source = "<python>";
  std::string units;               ///< dump `ITEM: UNITS` value; empty if unknown
  bool periodicity_stated = true;  ///< false for a data file (LAMMPS's default p p p assumed)
};
using AtomsPtr = std::shared_ptr<AtomsHandle>;

py::dict box_dict(const atomistic::Box& b) {
  py::dict d;
  d["lo"] = py::make_tuple(b.lo[0], b.lo[1], b.lo[2]);
  d["hi"] = py::make_tuple(b.hi[0], b.hi[1], b.hi[2]);
  d["tilt"] = py::make_tuple(b.xy, b.xz, b.yz);
  d["periodic"] = py::make_tuple(b.periodic[0], b.periodic[1], b.periodic[2]);
  d["h"] = matrix(b.h());
  return d;
}

std::vector<AtomsPtr> read_frames(const std::string& path, std::optional<std::int64_t> frame,
                                  const std::string& frames) {
  atomistic::FrameNeeds needs;
  needs.operation = "pdcg.read_atoms";
  needs.id = !frames.empty();
  std::string units;
  std::vector<atomistic::Atoms> conf;
  {
    py::gil_scoped_release release;
    conf = atomistic::read_configurations(path, frame, frames, &units, needs, {"frame", "frames"});
  }
  const bool data = atomistic::detect_atom_file_kind(path) == atomistic::AtomFileKind::data;
  std::vector<AtomsPtr> out;
  for (auto& a : conf) {
    auto h = std::make_shared<AtomsHandle>();
    h->atoms = std::move(a);
    h->source = path;
    h->units = units;
    h->periodicity_stated = !data;
    out.push_back(std::move(h));
  }
  return out;
}

AtomsPtr make_atoms(py::handle ids, py::handle types, py::handle positions, py::handle lo,
                    py::handle hi, py::handle tilt, py::handle periodic, py::handle type_mass,
                    py::handle masses, std::string source, py::handle bonds) {
  auto x = rows3(positions, "positions");
  const auto n = static_cast<std::size_t>(x.shape(0));
  auto id = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(ids);
  auto ty = py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(types);
  if (!id || id.ndim() != 1 || static_cast<std::size_t>(id.shape(0)) != n)
    throw InputError("ids do not match the positions")
        .source(source)
        .key("ids")
        .expected(fmt::format("{} integer ids (one per row of positions)", n));
  if (!ty || ty.ndim() != 1 || static_cast<std::size_t>(ty.shape(0)) != n)
    throw InputError("types do not match the positions")
        .source(source)
        .key("types")
        .expected(fmt::format("{} integer types 1..ntypes (one per row of positions)", n));
  auto h = std::make_shared<AtomsHandle>();
  h->source = source;
  auto& a = h->atoms;
  a.id.assign(id.data(), id.data() + n);
  a.type.assign(ty.data(), ty.data() + n);
  a.x.assign(x.data(), x.data() + 3 * n);
  for (std::size_t i = 0; i < 3 * n; ++i)
    if (!std::isfinite(a.x[i]))
      throw InputError("position is not finite")
          .source(source)
          .key(fmt::format("positions[{}]", i / 3))
          .value(fmt::format("{}", a.x[i]))
          .expected("finite coordinates");
  for (std::size_t i = 0; i < n; ++i)
    if (a.type[i] < 1)
      throw InputError("atom type out of range")
          .source(source)
          .key(fmt::format("types[{}] (id {})", i, a.id[i]))
          .value(std::to_string(a.type[i]))
          .expected("LAMMPS types 1..ntypes");
  auto v3 = [&](py::handle o, const char* name) {
    auto t = py::cast<std::vector<double>>(o);
    if (t.size() != 3) throw InputError("needs three values").key(name).expected("(x, y, z)");
    return Eigen::Vector3d(t[0], t[1], t[2]);
  };
  a.box.lo = v3(lo, "box lo");
  a.box.hi = v3(hi, "box hi");
  const Eigen::Vector3d t = v3(tilt, "tilt");
  a.box.xy = t[0];
  a.box.xz = t[1];
  a.box.yz = t[2];
  const auto p = py::cast<std::vector<bool>>(periodic);
  if (p.size() != 3) throw InputError("needs three values").key("periodic").expected("3 booleans");
  a.box.periodic = {p[0], p[1], p[2]};
  for (int k = 0; k < 3; ++k)
    if (!(a.box.hi[k] > a.box.lo[k]))
      throw InputError("box has no extent")
          .source(source)
          .key("box")
          .value(fmt::format("lo {} hi {} along {}", a.box.lo[k], a.box.hi[k], "xyz"[k]))
          .expected("hi > lo along every direction");
  if (!type_mass.is_none()) {
    const auto m = py::cast<std::vector<double>>(type_mass);
    a.type_mass.assign(1, std::numeric_limits<double>::quiet_NaN());
    a.type_mass.insert(a.type_mass.end(), m.begin(), m.end());
  }
  if (!masses.is_none()) {
    const auto m = py::cast<std::vector<double>>(masses);
    if (m.size() != n)
      throw InputError("masses do not match the positions")
          .key("masses")
          .expected(fmt::format("{} per-atom masses", n));
    a.mass = m;
  }
  if (!bonds.is_none()) {
    auto bd = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(bonds);
    if (!bd || bd.ndim() != 2 || bd.shape(1) != 3)
      throw InputError("wrong array shape")
          .source(source)
          .key("bonds")
          .expected("an (M, 3) integer array: bond type, atom id 1, atom id 2");
    for (py::ssize_t i = 0; i < bd.shape(0); ++i) {
      atomistic::Bond b;
      b.type = static_cast<int>(bd.at(i, 0));
      b.atom1 = bd.at(i, 1);
      b.atom2 = bd.at(i, 2);
      if (b.type < 1)
        throw InputError("bond type out of range")
            .source(source)
            .key(fmt::format("bonds[{}]", i))
            .value(std::to_string(b.type))
            .expected("bond types 1..nbondtypes");
      a.bonds.push_back(b);
    }
  }
  const int top = n ? *std::max_element(a.type.begin(), a.type.end()) : 0;
  a.ntypes = std::max<int>(top, a.type_mass.empty() ? 0 : static_cast<int>(a.type_mass.size()) - 1);
  atomistic::sort_by_id(a, source);
  return h;
}

// ---- Body ---------------------------------------------------------------------------------

/// A body and its evaluator (the evaluator holds a reference to the body: both live here).
struct BodyHandle {
  std::shared_ptr<body::Body> body;
  std::unique_ptr<body::Evaluator> evaluator;
  std::mutex mutex;  ///< one evaluation at a time (the evaluator owns its work arrays)
  bool have_reference = false;
  double ref_energy = 0.0;
  std::vector<double> ref_forces, ref_psi;

  explicit BodyHandle(body::Body b) : body(std::make_shared<body::Body>(std::move(b))) {}
};
using BodyPtr = std::shared_ptr<BodyHandle>;

/// Evaluates at the reference (y empty) or at deformed positions y (3N, a view of the caller's
/// array); writes forces (3N) and ψ (N) into the caller's arrays (one copy out of the
/// evaluator's work arrays, which the next evaluation reuses). Called without the GIL.
double evaluate(BodyHandle& h, std::span<const double> y, const std::optional<Eigen::Matrix3d>& hy,
                double* forces, double* psi, std::vector<double>* point_energies) {
  std::lock_guard lock(h.mutex);
  if (!h.evaluator) h.evaluator = std::make_unique<body::Evaluator>(*h.body);
  body::Evaluation e;
  if (y.empty())
    e = h.evaluator->reference();
  else if (hy)
    e = h.evaluator->deformed(y, *hy);
  else
    e = h.evaluator->deformed(y);
  std::copy(e.forces.begin(), e.forces.end(), forces);
  std::copy(e.psi.begin(), e.psi.end(), psi);
  if (h.body->homogenisation) *point_energies = h.evaluator->point_energies();
  return e.energy;
}

/// The number of atom types of a configuration: declared (data file), else the largest type.
int atom_types(const AtomsHandle& h) {
  const auto& a = h.atoms;
  int n = a.ntypes;
  if (n == 0 && !a.type.empty()) n = *std::max_element(a.type.begin(), a.type.end());
  // per-type-pair tables hold (ntypes+1)² entries per coefficient (as `pdcg atoms2pd`)
  constexpr int kMaxTypes = 10000;
  if (n > kMaxTypes)
    throw InputError("too many atom types")
        .source(h.source)
        .key("atom types")
        .value(std::to_string(n))
        .expected(fmt::format("at most {} types (per-type-pair tables grow as types²)", kMaxTypes));
  return n;
}

/// The potential's commands: a file (`potential`) or text (`commands`), exactly one.
atomistic::PotentialSpec read_spec(const std::string& potential, const std::string& commands,
                                   int ntypes) {
  if (potential.empty() == commands.empty())
    throw InputError("give exactly one of potential= and commands=")
        .key("potential/commands")
        .fix("potential=\"pot.in\" (a file of LAMMPS commands) or commands=\"pair_style …\"");
  return potential.empty()
             ? atomistic::read_potential_commands_from_string(commands, "<commands>", ntypes)
             : atomistic::read_potential_commands(potential, ntypes);
}

struct BodyArgs {
  std::string potential, commands, boundary;
  int dimension = 3;
  std::optional<double> family_cutoff;
};

/// The periodicity rules of `pdcg atoms2pd` (docs/atomistic-input.md, "Periodicity"): the
/// `boundary=` argument wins, then the commands' `boundary`, then the configuration's box
/// (dump header, LAMMPS instance, ASE pbc); a data file states nothing (p p p assumed).
std::pair<std::array<bool, 3>, bool> periodicity(const AtomsHandle& h,
                                                 const atomistic::PotentialSpec& spec,
                                                 const std::string& boundary) {
  std::array<bool, 3> p = h.atoms.box.periodic;
  bool stated = h.periodicity_stated;
  if (spec.periodic) {
    if (stated && *spec.periodic != p)
      log::warn("`boundary {}` ({}:{}) wins over the periodicity of {}", spec.boundary, spec.source,
                spec.boundary_line, h.source);
    p = *spec.periodic;
    stated = true;
  }
  if (!boundary.empty()) {
    const auto b = atomistic::parse_boundary(boundary, "boundary=", 0, "boundary");
    if (stated && b != p) log::warn("boundary=\"{}\" wins over the stated periodicity", boundary);
    p = b;
    stated = true;
  }
  return {p, !stated};
}

/// `pdcg atoms2pd` for configurations held in memory: a delta body of frames[0], or (with
/// `statistics`) a statistical body of all frames (docs/theory.md §1–2).
body::Body build_body(std::vector<AtomsPtr> frames_in, const BodyArgs& args,
                      const std::string& statistics, std::optional<double> width,
                      std::optional<int> order, std::optional<std::int64_t> samples,
                      std::optional<double> temperature = std::nullopt) {
  if (frames_in.empty()) throw InputError("no configuration given").key("atoms");
  const AtomsHandle& ref_h = *frames_in.front();
  std::vector<atomistic::Atoms> frames;
  for (const auto& f : frames_in) frames.push_back(f->atoms);
  atomistic::Atoms& ref = frames.front();
  const int ntypes = atom_types(ref_h);
  atomistic::PotentialSpec spec = read_spec(args.potential, args.commands, ntypes);
  const auto [periodic, assumed] = periodicity(ref_h, spec, args.boundary);
  for (auto& f : frames) f.box.periodic = periodic;
  if (!ref_h.units.empty() && ref_h.units != to_string(spec.units))
    throw InputError("the dump and the potential use different units")
        .source(ref_h.source)
        .key("ITEM: UNITS")
        .value(ref_h.units)
        .expected(fmt::format("'{}' (the `units` of {})", to_string(spec.units), spec.source))
        .fix("use the potential the trajectory was produced with");
  atomistic::take_type_charges(spec, ref);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  body::BodyRequest request;
  request.delta.dimension = args.dimension;
  request.delta.source = ref_h.source;
  request.delta.periodicity_assumed = assumed;
  request.family_cutoff = args.family_cutoff;
  request.statistics = statistics;
  request.width = width;
  request.temperature = temperature;
  request.order = order;
  request.samples = samples;
  request.provenance = fmt::format(" (potential {}, Python module)", spec.source);
  request.spelling = body::OptionSpelling::python;
  return body::build_body(frames, pot, spec, request);
}

// ---- progress -----------------------------------------------------------------------------

/// Installs a Python progress callback for the duration of one call (GIL taken per call).
class ProgressScope {
 public:
  explicit ProgressScope(const py::object& callback) {
    if (callback.is_none()) return;
    auto cb = std::make_shared<py::object>(callback);
    Progress::set_observer([cb](const std::string& label, std::uint64_t done, std::uint64_t total) {
      py::gil_scoped_acquire gil;
      (*cb)(label, done, total);  // a Python exception propagates as error_already_set
    });
    active_ = true;
  }
  ~ProgressScope() {
    if (active_) Progress::set_observer({});
  }

 private:
  bool active_ = false;
};

}  // namespace

PYBIND11_MODULE(_pdcg, m) {
  m.doc() = "Compiled core of the pdcg Python module (use `import pdcg`).";

  // Errors: pdcg.Error (RuntimeError), pdcg.InputError (Error, ValueError), pdcg.NumericalError.
  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  static py::handle input_error, numerical_error;
  {
    py::object bases = py::make_tuple(error, py::handle(PyExc_ValueError));
    input_error = PyErr_NewExceptionWithDoc(
        "pdcg._pdcg.InputError",
        "Bad input (file, line, key, value, what was expected, the fix): pdcg::InputError.",
        bases.ptr(), nullptr);
    numerical_error = PyErr_NewExceptionWithDoc(
        "pdcg._pdcg.NumericalError",
        "A numerical failure with its diagnosis: pdcg::NumericalError.", error.ptr(), nullptr);
    m.attr("InputError") = input_error;
    m.attr("NumericalError") = numerical_error;
  }
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const NumericalError& e) {
      PyErr_SetString(numerical_error.ptr(), e.what());
    } catch (const Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });

  m.def("version", &pdcg::version, "pdcg's version string.");
  m.def(
      "set_log_level",
      [](const std::string& level) {
        if (level == "debug")
          log::set_level(log::Level::debug);
        else if (level == "info")
          log::set_level(log::Level::info);
        else if (level == "warn" || level == "warning")
          log::set_level(log::Level::warn);
        else if (level == "error")
          log::set_level(log::Level::error);
        else
          throw InputError("unknown log level")
              .key("level")
              .value(level)
              .expected("debug, info, warn or error");
      },
      py::arg("level"), "Log level of pdcg's messages on stderr: debug, info, warn, error.");

  // ---- Atoms ----
  py::class_<AtomsHandle, AtomsPtr>(m, "Atoms", R"doc(
One configuration of atoms (a dump frame, a data file, a LAMMPS instance, ASE Atoms).
Arrays are read-only numpy views of pdcg's memory (no copy); they keep the configuration alive.
Positions are unwrapped when the file gives image flags (docs/atomistic-input.md).)doc")
      .def(py::init(&make_atoms), py::arg("ids"), py::arg("types"), py::arg("positions"),
           py::arg("lo"), py::arg("hi"), py::arg("tilt") = py::make_tuple(0.0, 0.0, 0.0),
           py::arg("periodic") = py::make_tuple(true, true, true),
           py::arg("type_mass") = py::none(), py::arg("masses") = py::none(),
           py::arg("source") = "<python>", py::arg("bonds") = py::none(),
           "Atoms from arrays: ids (N), types (N, 1-based), positions (N, 3), the LAMMPS box "
           "(lo, hi, tilt xy xz yz), periodic flags, masses per type (type_mass[t-1]) or per atom. "
           "Sorted by id; InputError for duplicate ids, non-finite positions, types < 1. `bonds`: "
           "molecular bonds (M, 3): bond type, atom id 1, atom id 2.")
      .def_property_readonly("ids",
                             [](const AtomsPtr& h) {
                               return view(h, h->atoms.id.data(),
                                           {static_cast<py::ssize_t>(h->atoms.size())});
                             })
      .def_property_readonly("types",
                             [](const AtomsPtr& h) -> py::object {
                               if (h->atoms.type.empty()) return py::none();
                               return view(h, h->atoms.type.data(),
                                           {static_cast<py::ssize_t>(h->atoms.size())});
                             })
      .def_property_readonly(
          "positions",
          [](const AtomsPtr& h) {
            return view(h, h->atoms.x.data(), {static_cast<py::ssize_t>(h->atoms.size()), 3});
          })
      .def_property_readonly(
          "velocities",
          [](const AtomsPtr& h) -> py::object {
            if (h->atoms.v.empty()) return py::none();
            return view(h, h->atoms.v.data(), {static_cast<py::ssize_t>(h->atoms.size()), 3});
          })
      .def_property_readonly(
          "forces",
          [](const AtomsPtr& h) -> py::object {
            if (h->atoms.f.empty()) return py::none();
            return view(h, h->atoms.f.data(), {static_cast<py::ssize_t>(h->atoms.size()), 3});
          })
      .def_property_readonly(
          "type_mass",
          [](const AtomsPtr& h) -> py::object {
            if (h->atoms.type_mass.size() < 2) return py::none();
            return view(h, h->atoms.type_mass.data() + 1,
                        {static_cast<py::ssize_t>(h->atoms.type_mass.size() - 1)});
          },
          "Mass per type, index t-1 for type t (NaN where unknown); None if the source has none.")
      .def_property_readonly(
          "box", [](const AtomsPtr& h) { return box_dict(h->atoms.box); },
          "The LAMMPS box: lo, hi, tilt (xy, xz, yz), periodic, h = [a b c].")
      .def_property_readonly(
          "bonds",
          [](const AtomsPtr& h) {
            py::array_t<std::int64_t> b(
                {static_cast<py::ssize_t>(h->atoms.bonds.size()), py::ssize_t{3}});
            auto r = b.mutable_unchecked<2>();
            for (std::size_t i = 0; i < h->atoms.bonds.size(); ++i) {
              const auto k = static_cast<py::ssize_t>(i);
              r(k, 0) = h->atoms.bonds[i].type;
              r(k, 1) = h->atoms.bonds[i].atom1;
              r(k, 2) = h->atoms.bonds[i].atom2;
            }
            return b;
          },
          "Molecular bonds (M, 3): type, atom id 1, atom id 2 (a copy).")
      .def_property_readonly("timestep", [](const AtomsPtr& h) { return h->atoms.timestep; })
      .def_property_readonly("ntypes", [](const AtomsPtr& h) { return atom_types(*h); })
      .def_property_readonly("source", [](const AtomsPtr& h) { return h->source; })
      .def_property_readonly(
          "units", [](const AtomsPtr& h) { return h->units; },
          "The dump's ITEM: UNITS (empty if it has none).")
      .def_property_readonly(
          "columns",
          [](const AtomsPtr& h) {
            std::vector<std::string> k;
            for (const auto& [name, v] : h->atoms.extra) k.push_back(name);
            return k;
          },
          "Names of the other per-atom columns (see column()).")
      .def(
          "column",
          [](const AtomsPtr& h, const std::string& name) {
            auto it = h->atoms.extra.find(name);
            if (it == h->atoms.extra.end())
              throw InputError("no such column")
                  .source(h->source)
                  .key(name)
                  .fix("Atoms.columns lists the columns");
            return view(h, it->second.data(), {static_cast<py::ssize_t>(it->second.size())});
          },
          py::arg("name"))
      .def("__len__", [](const AtomsPtr& h) { return h->atoms.size(); })
      .def("__repr__", [](const AtomsPtr& h) {
        return fmt::format("<pdcg.Atoms {} atoms from {}>", h->atoms.size(), h->source);
      });

  m.def(
      "read_atoms",
      [](const std::string& path, std::int64_t frame) {
        return read_frames(path, frame, "").front();
      },
      py::arg("path"), py::arg("frame") = -1,
      R"doc(One configuration of a LAMMPS dump (frame, 0-based, negative from the end; -1 the last)
or a data file (frame 0 or -1). The kind is told from the content (docs/atomistic-input.md).)doc");
  m.def(
      "read_frames",
      [](const std::string& path, const std::string& frames) {
        return read_frames(path, std::nullopt, frames);
      },
      py::arg("path"), py::arg("frames"),
      "Frames A:B[:S] of a dump (B inclusive, negative from the end; the syntax of `pdcg atoms2pd "
      "--frames`), as a list of Atoms.");

  // ---- Body ----
  py::class_<BodyHandle, BodyPtr>(m, "Body", py::dynamic_attr(), R"doc(
A peridynamic body made from atoms (docs/theory.md §1–4): delta, statistical, homogenised or
rescaled. Holds its potential (shared): it outlives the atoms and files it came from.
Arrays are read-only numpy views (no copy) that keep the body alive.)doc")
      .def_property_readonly(
          "kind", [](const BodyPtr& h) { return std::string(body::to_string(h->body->kind)); })
      .def_property_readonly(
          "units", [](const BodyPtr& h) { return std::string(to_string(h->body->units)); })
      .def_property_readonly("dimension", [](const BodyPtr& h) { return h->body->dimension; })
      .def_property_readonly("ids",
                             [](const BodyPtr& h) {
                               return view(h, h->body->id.data(),
                                           {static_cast<py::ssize_t>(h->body->size())});
                             })
      .def_property_readonly("types",
                             [](const BodyPtr& h) {
                               return view(h, h->body->type.data(),
                                           {static_cast<py::ssize_t>(h->body->size())});
                             })
      .def_property_readonly(
          "positions",
          [](const BodyPtr& h) {
            return view(h, h->body->x.data(), {static_cast<py::ssize_t>(h->body->size()), 3});
          },
          "Reference positions x_k (N, 3).")
      .def_property_readonly(
          "masses",
          [](const BodyPtr& h) {
            return view(h, h->body->mass.data(), {static_cast<py::ssize_t>(h->body->size())});
          },
          "Point masses M_k (N).")
      .def_property_readonly("box", [](const BodyPtr& h) { return box_dict(h->body->box); })
      .def_property_readonly("horizon", [](const BodyPtr& h) { return h->body->horizon(); })
      .def_property_readonly(
          "epsilon", [](const BodyPtr& h) { return h->body->epsilon; },
          "Rescaling factor ε applied so far (docs/theory.md §4).")
      .def_property_readonly("reference_volume",
                             [](const BodyPtr& h) { return h->body->reference_volume(); })
      .def_property_readonly("bonds", [](const BodyPtr& h) { return h->body->families.bonds(); })
      .def_property_readonly(
          "family_offsets",
          [](const BodyPtr& h) {
            const auto& f = h->body->families;
            return view(h, f.offset.data(), {static_cast<py::ssize_t>(f.offset.size())});
          },
          "CSR offsets of the families: bonds of point k are family_neighbors[off[k]:off[k+1]].")
      .def_property_readonly("family_neighbors",
                             [](const BodyPtr& h) {
                               const auto& f = h->body->families;
                               return view(h, f.neighbor.data(),
                                           {static_cast<py::ssize_t>(f.neighbor.size())});
                             })
      .def_property_readonly("potential_style",
                             [](const BodyPtr& h) {
                               return h->body->potential ? h->body->potential->style()
                                                         : std::string();
                             })
      .def_property_readonly(
          "potential_commands", [](const BodyPtr& h) { return h->body->potential_spec.lines; },
          "The LAMMPS command lines of the potential, as stored in a model file.")
      .def_property_readonly("provenance", [](const BodyPtr& h) { return h->body->provenance; })
      .def_property_readonly(
          "points",
          [](const BodyPtr& h) -> py::object {
            const auto& hm = h->body->homogenisation;
            if (!hm) return py::none();
            return view(h, hm->points.data(), {static_cast<py::ssize_t>(hm->size()), 3});
          },
          "Homogenised bodies: continuum points x_p (P, 3) (docs/theory.md §3); else None.")
      .def_property_readonly("point_volumes",
                             [](const BodyPtr& h) -> py::object {
                               const auto& hm = h->body->homogenisation;
                               if (!hm) return py::none();
                               return view(h, hm->volume.data(),
                                           {static_cast<py::ssize_t>(hm->size())});
                             })
      .def_property_readonly(
          "point_masses",
          [](const BodyPtr& h) -> py::object {
            const auto& hm = h->body->homogenisation;
            if (!hm) return py::none();
            return view(h, hm->mass.data(), {static_cast<py::ssize_t>(hm->size())});
          },
          "m_p = Σ_k w_kp M_k (docs/theory.md §3).")
      .def(
          "_evaluate",
          [](const BodyPtr& h, py::object positions, py::object box_h) {
            std::optional<Eigen::Matrix3d> hy;
            const auto n = static_cast<py::ssize_t>(h->body->size());
            py::array_t<double, py::array::c_style | py::array::forcecast> a;
            std::span<const double> y;
            if (!positions.is_none()) {
              a = rows3(positions, "positions");  // a view when already C-contiguous doubles
              if (a.shape(0) != n)
                throw InputError("deformed positions do not match the body")
                    .key("positions")
                    .value(fmt::format("{} rows", a.shape(0)))
                    .expected(fmt::format("{} rows, in the order of Body.ids", n));
              y = {a.data(), static_cast<std::size_t>(3 * n)};
            } else if (!box_h.is_none()) {
              throw InputError("a deformed box needs deformed positions").key("h");
            }
            if (!box_h.is_none()) hy = mat3(box_h, "h");
            py::array_t<double> f({n, py::ssize_t{3}}), psi(n);
            double* fp = f.mutable_data();
            double* pp = psi.mutable_data();
            std::vector<double> pe;
            double energy = 0.0;
            {
              py::gil_scoped_release release;  // `a` keeps the positions alive meanwhile
              energy = evaluate(*h, y, hy, fp, pp, &pe);
            }
            py::object pe_out = py::none();
            if (h->body->homogenisation)
              pe_out = copy_of<double>(pe, {static_cast<py::ssize_t>(pe.size())});
            return py::make_tuple(energy, f, psi, pe_out);
          },
          py::arg("positions") = py::none(), py::arg("h") = py::none())
      .def(
          "write",
          [](const BodyPtr& h, const std::string& path) {
            py::gil_scoped_release release;
            body::write_body(*h->body, path);
          },
          py::arg("path"), "Writes the model file (HDF5 pdcg-body, docs/formats.md), atomically.")
      .def(
          "stress",
          [](const BodyPtr& h, const std::optional<std::vector<double>>& F_rows) {
            Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
            if (F_rows) {
              if (F_rows->size() != 9)
                throw InputError("F must hold 9 numbers (row-major 3×3)")
                    .key("F")
                    .value(std::to_string(F_rows->size()) + " numbers");
              for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                  F(r, c) = (*F_rows)[static_cast<std::size_t>(3 * r + c)];
            }
            if (!(F.determinant() > 0.0))
              throw InputError("deformation gradient with det F ≤ 0")
                  .key("F")
                  .value(fmt::format("det F = {:.6g}", F.determinant()));
            Eigen::Matrix3d P;
            {
              py::gil_scoped_release release;
              std::lock_guard lock(h->mutex);
              if (!h->evaluator) h->evaluator = std::make_unique<body::Evaluator>(*h->body);
              P = h->evaluator->stress(F);
            }
            py::array_t<double> out({3, 3});
            auto o = out.mutable_unchecked<2>();
            for (int r = 0; r < 3; ++r)
              for (int c = 0; c < 3; ++c) o(r, c) = P(r, c);
            return out;
          },
          py::arg("F") = py::none(),
          "First Piola–Kirchhoff stress P = ∂W/∂F (3×3, energy per reference volume) of the "
          "homogeneous deformation F (9 numbers row-major; default identity). Statistical "
          "bodies: the expected value, fluctuations carried by F; at F = I minus the virial part "
          "of LAMMPS's pressure tensor (docs/temperature.md).")
      .def("__len__", [](const BodyPtr& h) { return h->body->size(); })
      .def("__repr__", [](const BodyPtr& h) {
        const auto& b = *h->body;
        return fmt::format("<pdcg.Body {} body, {} points, {} bonds, horizon {:.6g}, units {}>",
                           body::to_string(b.kind), b.size(), b.families.bonds(), b.horizon(),
                           to_string(b.units));
      });

  m.def(
      "read_body",
      [](const std::string& path) {
        body::Body b;
        {
          py::gil_scoped_release release;
          b = body::read_body(path);
        }
        return std::make_shared<BodyHandle>(std::move(b));
      },
      py::arg("path"),
      "Reads a model file (pdcg-body, docs/formats.md) written by pdcg or Body.write.");

  m.def(
      "_build_body",
      [](std::vector<AtomsPtr> frames, const std::string& potential, const std::string& commands,
         int dimension, std::optional<double> family_cutoff, const std::string& boundary,
         const std::string& statistics, std::optional<double> width, std::optional<int> order,
         std::optional<std::int64_t> samples, std::optional<double> temperature) {
        BodyArgs args;
        args.potential = potential;
        args.commands = commands;
        args.dimension = dimension;
        args.family_cutoff = family_cutoff;
        args.boundary = boundary;
        body::Body b;
        {
          py::gil_scoped_release release;
          b = build_body(std::move(frames), args, statistics, width, order, samples, temperature);
        }
        return std::make_shared<BodyHandle>(std::move(b));
      },
      py::arg("frames"), py::arg("potential"), py::arg("commands"), py::arg("dimension"),
      py::arg("family_cutoff"), py::arg("boundary"), py::arg("statistics"), py::arg("width"),
      py::arg("order"), py::arg("samples"), py::arg("temperature") = py::none());

  m.def(
      "_potential_info",
      [](const std::string& potential, const std::string& commands, int ntypes) {
        const auto spec = read_spec(potential, commands, ntypes);
        py::dict d;
        d["units"] = std::string(to_string(spec.units));
        d["pair_style"] = spec.pair_style;
        d["bond_style"] = spec.bond_style;
        d["atom_style"] = spec.atom_style;
        d["ntypes"] = spec.ntypes;
        d["boundary"] = spec.boundary;
        std::vector<std::vector<std::string>> coeffs;
        for (const auto& c : spec.pair_coeff) {
          std::vector<std::string> w{c.i, c.j};
          w.insert(w.end(), c.args.begin(), c.args.end());
          coeffs.push_back(w);
        }
        d["pair_coeff"] = coeffs;
        d["lines"] = spec.lines;
        return d;
      },
      py::arg("potential"), py::arg("commands"), py::arg("ntypes") = 0);

  // ---- coarse-graining ----
  m.def(
      "homogenize",
      [](const BodyPtr& h, const std::string& kernel, double width, std::optional<double> spacing,
         py::object points, py::object axes, py::object shift) {
        const coarsen::Kernel k = coarsen::make_kernel(kernel, width);
        if (spacing.has_value() == !points.is_none())
          throw InputError("give exactly one of spacing= and points=")
              .key("spacing/points")
              .fix("spacing=H for a regular grid, points=(P, 3) array for given points");
        std::vector<double> pts;
        coarsen::GridOptions g;
        if (!points.is_none()) {
          auto a = rows3(points, "points");
          pts.assign(a.data(), a.data() + a.size());
        } else {
          g.spacing = *spacing;
          if (!axes.is_none()) {
            g.rotation = mat3(axes, "axes").transpose();  // rows given = grid axes
            if (!(g.rotation.transpose() * g.rotation)
                     .isApprox(Eigen::Matrix3d::Identity(), 1e-8) ||
                g.rotation.determinant() < 0)
              throw InputError("grid axes are not orthonormal and right-handed")
                  .key("axes")
                  .expected("three orthonormal rows a, b, c with a × b = c");
          }
          if (!shift.is_none()) {
            const auto s = py::cast<std::vector<double>>(shift);
            if (s.size() != 3) throw InputError("needs three values").key("shift");
            g.shift = {s[0], s[1], s[2]};
          }
        }
        body::Body out;
        {
          py::gil_scoped_release release;
          out = points.is_none() ? coarsen::homogenise_on_grid(*h->body, k, g)
                                 : coarsen::homogenise_on_points(*h->body, k, std::move(pts));
        }
        return std::make_shared<BodyHandle>(std::move(out));
      },
      py::arg("body"), py::arg("kernel"), py::arg("width"), py::arg("spacing") = py::none(),
      py::arg("points") = py::none(), py::arg("axes") = py::none(), py::arg("shift") = py::none(),
      R"doc(Homogenises a body (docs/theory.md §3): w_kp = φ(|x_k − x_p|) / Σ_q φ(|x_k − x_q|),
m_p = Σ_k w_kp M_k, E_p(Y) = Σ_k w_kp ψ_k(Y). Kernels: top-hat, gaussian, cubic-bspline,
wendland-c2 (width: support radius; σ for gaussian). A regular grid of `spacing` (optionally
`axes` as rows and `shift` in spacings) or given `points` (P, 3). `pdcg homogenize`.)doc");

  m.def(
      "rescale",
      [](const BodyPtr& h, std::optional<double> factor, std::optional<double> horizon) {
        if (factor.has_value() == horizon.has_value())
          throw InputError("give exactly one of factor= and horizon=")
              .key("factor/horizon")
              .fix("factor=EPS (ε = δ'/δ) or horizon=D (the new horizon δ')");
        body::Body out;
        {
          py::gil_scoped_release release;
          const double eps = factor ? *factor : coarsen::epsilon_for_horizon(*h->body, *horizon);
          out = coarsen::rescale(*h->body, eps);
        }
        return std::make_shared<BodyHandle>(std::move(out));
      },
      py::arg("body"), py::arg("factor") = py::none(), py::arg("horizon") = py::none(),
      R"doc(Rescales the horizon (docs/theory.md §4): ε = δ'/δ, W_ε(Y) = W(E(Y)),
(E(Y))⟨ξ⟩ = ε⁻¹ Y⟨εξ⟩; bonds εξ, masses and energies ×ε^d. `pdcg rescale`.)doc");

  // ---- elastic constants ----
  m.def(
      "_elastic",
      [](const BodyPtr& h, py::object F_in) {
        Eigen::Matrix3d F = F_in.is_none() ? Eigen::Matrix3d::Identity() : mat3(F_in, "F");
        if (!(F.determinant() > 0.0))
          throw InputError("deformation gradient with det F ≤ 0")
              .key("F")
              .value(fmt::format("det F = {:.6g}", F.determinant()))
              .expected("det F > 0");
        const auto& b = *h->body;
        if (b.dimension == 2 && (F(0, 2) != 0.0 || F(1, 2) != 0.0 || F(2, 0) != 0.0 ||
                                 F(2, 1) != 0.0 || F(2, 2) != 1.0))
          throw InputError("2D body: F must be a plane-strain deformation")
              .key("F")
              .expected("F13 = F23 = F31 = F32 = 0 and F33 = 1");
        body::CauchyBornState st;
        body::Matrix6d C;
        body::Moduli mod;
        body::LatticeInfo lat;
        body::LatticeNote note;
        {
          py::gil_scoped_release release;
          const body::CauchyBorn cb(b);
          st = cb.evaluate(F);
          C = body::voigt_elastic_constants(F, st);
          mod = body::moduli(C, b.dimension);
          lat = cb.lattice();
          note = body::cauchy_born_lattice_note(lat);
        }
        py::dict d;
        d["F"] = matrix(F);
        d["W"] = st.W;
        d["P"] = matrix(st.P);
        d["S"] = matrix(F.inverse() * st.P);
        d["A"] = matrix(st.A);
        d["C_voigt"] = matrix(C);
        d["units"] = std::string(to_string(b.units));
        d["unit"] = std::string(unit_names(b.units).energy_density);
        d["to_GPa"] = energy_density_to_gpa(b.units);
        d["bulk_voigt"] = mod.bulk_voigt;
        d["shear_voigt"] = mod.shear_voigt;
        d["bulk_reuss"] = mod.bulk_reuss;
        d["shear_reuss"] = mod.shear_reuss;
        d["lattice"] = lat.summary;
        d["note"] = note.text;
        return d;
      },
      py::arg("body"), py::arg("F") = py::none());

  // ---- dispersion ----
  m.def(
      "_dispersion",
      [](const BodyPtr& h, const std::string& path, py::object direction, int nk,
         std::optional<double> kmax, std::string lattice, std::optional<double> a_in,
         std::optional<std::size_t> point, bool cell) {
        const auto& b = *h->body;
        if (path.empty() == direction.is_none())
          throw InputError("give exactly one of path= and direction=")
              .key("path/direction")
              .expected("path='G-X-W-K-G-L' or direction=(1, 0, 0)");
        if (nk < 1) throw InputError("nk must be at least 1").key("nk").value(std::to_string(nk));
        Eigen::Vector3d dir = Eigen::Vector3d::Zero();
        if (!direction.is_none()) {
          const auto v = py::cast<std::vector<double>>(direction);
          if (v.size() != 3 || Eigen::Vector3d(v[0], v[1], v[2]).norm() == 0.0)
            throw InputError("a direction needs three components, not all zero")
                .key("direction")
                .expected("e.g. (1, 0, 0)");
          dir = Eigen::Vector3d(v[0], v[1], v[2]).normalized();
        }
        dispersion::DispersionRequest request;
        request.path = path;
        if (path.empty()) {
          request.direction = dir;
          const auto v = py::cast<std::vector<double>>(direction);
          request.direction_text = fmt::format("({}, {}, {})", v[0], v[1], v[2]);
        }
        request.nk = nk;
        request.kmax = kmax.value_or(0.0);
        request.lattice = lattice;
        request.a = a_in.value_or(0.0);
        request.point = point;
        request.cell = cell;
        // the option names of pdcg.dispersion in the messages (the CLI's are the defaults)
        dispersion::DispersionOptionNames names;
        names.path = "path";
        names.path_auto = "path='auto'";
        names.direction = "direction";
        names.lattice = "lattice";
        names.a = "a";
        names.cell = "cell=True";
        names.point = "point";
        std::vector<std::pair<double, Eigen::Vector3d>> ks;
        std::vector<std::pair<double, std::string>> labels;
        std::vector<Eigen::VectorXd> omega;
        std::string description;
        double a = 0.0;
        {
          py::gil_scoped_release release;
          // the selection of `pdcg dispersion` (crystal with a basis: 3n branches;
          // dispersion/plan.hpp)
          const auto plan = dispersion::plan_dispersion(b, request, names);
          ks = plan.kappa;
          labels = plan.corners();
          lattice = plan.lattice;
          a = plan.a;
          description = plan.description();
          omega.reserve(ks.size());
          for (const auto& [s, k] : ks) omega.push_back(plan.omega(k));
        }
        const auto n = static_cast<py::ssize_t>(ks.size());
        const auto nb = static_cast<py::ssize_t>(omega.empty() ? 0 : omega[0].size());
        py::array_t<double> kappa(n), kvec({n, py::ssize_t{3}}), om({n, nb});
        auto kr = kappa.mutable_unchecked<1>();
        auto kv = kvec.mutable_unchecked<2>();
        auto wr = om.mutable_unchecked<2>();
        for (py::ssize_t i = 0; i < n; ++i) {
          kr(i) = ks[static_cast<std::size_t>(i)].first;
          for (int c = 0; c < 3; ++c) kv(i, c) = ks[static_cast<std::size_t>(i)].second[c];
          for (py::ssize_t j = 0; j < nb; ++j) wr(i, j) = omega[static_cast<std::size_t>(i)][j];
        }
        py::dict d;
        d["kappa"] = kappa;
        d["kvec"] = kvec;
        d["omega"] = om;
        d["labels"] = labels;
        d["lattice"] = lattice;
        d["a"] = a;
        d["description"] = description;
        d["units"] = std::string(to_string(b.units));
        d["kappa_unit"] = std::string(unit_names(b.units).wavenumber);
        d["omega_unit"] = std::string(unit_names(b.units).frequency);
        return d;
      },
      py::arg("body"), py::arg("path"), py::arg("direction"), py::arg("nk"), py::arg("kmax"),
      py::arg("lattice"), py::arg("a"), py::arg("point"), py::arg("cell"));

  // ---- scenes ----
  m.def(
      "_load_scene",
      [](const std::string& path) {
        const auto s = scene::load_scene(path);
        py::dict d;
        d["output_directory"] = s.output_directory.string();
        d["steps"] = s.steps;
        d["inertia"] = s.inertia;
        d["resolved_yaml"] = scene::resolved_yaml(s);
        return d;
      },
      py::arg("path"));
  m.def(
      "_run_scene",
      [](const std::string& path, const std::string& output, const std::string& restart,
         py::object progress) {
        const auto s = scene::load_scene(path);
        scene::RunOptions ro;
        if (!output.empty()) ro.output = output;
        if (!restart.empty()) ro.restart = restart;
        ProgressScope scope(progress);
        py::gil_scoped_release release;
        scene::run_scene(s, ro);
      },
      py::arg("path"), py::arg("output"), py::arg("restart"), py::arg("progress"));
}
