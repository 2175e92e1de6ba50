#pragma once
/// What `pdcg dispersion --path/--direction` and pdcg.dispersion(path=, direction=) compute:
/// the κ list (with path labels), the model that gives ω(κ) and its description. One place for
/// the choice, so the command line and the Python module cannot drift apart:
///  - --path on a perfect crystal with a basis (no --cell, no --lattice with --a): the primitive
///    cell's 3n branches (CrystalDispersion) along a labelled path of the classified lattice;
///    a homogenised body of such a crystal: its 3 one-point branches on that path;
///  - otherwise the one-point (or --cell) model BodyDispersion, on a path of the lattice from the
///    nearest-neighbour shell (or --lattice/--a), or along --direction up to the zone edge
///    (or --kmax).
/// Bad input (a defective or random crystal on a path, a crystal with a basis whose Bravais
/// lattice the shell cannot tell, an unknown label, ...) throws InputError naming the option as
/// the caller spells it (DispersionOptionNames: "--path" on the command line, "path" in Python).
#include <Eigen/Dense>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pdcg/body/body.hpp"

namespace pdcg::dispersion {

class BodyDispersion;
class CrystalDispersion;

/// How the caller spells the options in messages (defaults: the command line's).
struct DispersionOptionNames {
  std::string path = "--path";
  std::string path_auto = "--path auto";  ///< the example of an automatic path
  std::string direction = "--direction";
  std::string lattice = "--lattice";
  std::string a = "--a";
  std::string cell = "--cell";
  std::string point = "--point";
};

struct DispersionRequest {
  std::string path;                    ///< labels "G-X-W|U-X" or "auto"; "" = along `direction`
  Eigen::Vector3d direction{0, 0, 0};  ///< unit vector (when path is "")
  std::string direction_text;          ///< the direction as the user wrote it (messages)
  int nk = 50;                         ///< points per path segment / along the direction
  double kmax = 0.0;                   ///< ≤ 0: the zone edge along the direction
  std::string lattice;                 ///< "" = from the crystal
  double a = 0.0;                      ///< ≤ 0 = from the crystal
  std::optional<std::size_t> point;    ///< atom or homogenised point; nullopt: nearest the centre
  bool cell = false;                   ///< all atoms of the periodic box as the basis
  std::string source;                  ///< the body's file name for messages ("" when none)
};

class DispersionPlan {
 public:
  DispersionPlan();
  DispersionPlan(DispersionPlan&&) noexcept;
  DispersionPlan& operator=(DispersionPlan&&) noexcept;
  ~DispersionPlan();

  /// (path length or |κ|, κ) of every point, in order.
  std::vector<std::pair<double, Eigen::Vector3d>> kappa;
  /// Per κ: its path label ("" between corners; empty vector along a direction).
  std::vector<std::string> labels;
  /// The lattice and its constant the path belongs to ("" / 0 along a direction).
  std::string lattice;
  double a = 0.0;

  /// Frequencies at κ, ascending (3n for a crystal with a basis, 3 for a point, 3N for --cell).
  Eigen::VectorXd omega(const Eigen::Vector3d& kappa) const;
  std::string description() const;
  /// The labelled corners (position, label) as written in the CSV's "# path labels:" line:
  /// every labelled κ except an immediate repeat of the same label at the same position.
  std::vector<std::pair<double, std::string>> corners() const;

 private:
  friend DispersionPlan plan_dispersion(const body::Body&, const DispersionRequest&,
                                        const DispersionOptionNames&);
  std::unique_ptr<CrystalDispersion> crystal_;
  std::unique_ptr<BodyDispersion> point_;
};

/// The plan of `request` for `body` (which must outlive it). Cheap lattice checks come before
/// any linearisation. Logs the classified lattice (info) and warns when one-point branches of a
/// crystal with a basis miss its optical branches.
DispersionPlan plan_dispersion(const body::Body& body, const DispersionRequest& request,
                               const DispersionOptionNames& names = {});

/// The one-point models (--direction, --grid, and --path with --lattice/--a or --cell) treat the
/// point as a Bravais lattice site: nothing to check with `cell`; a defective crystal gets an info
/// line; a perfect crystal with a basis a warning (3(n − 1) optical branches missing), or for
/// --path without both --lattice and --a (`lattice_given` false) an InputError. `mode` names the
/// option in the messages.
void check_one_point_lattice(const body::Body& body, bool cell, const std::string& mode,
                             bool lattice_given, const std::string& source,
                             const DispersionOptionNames& names = {});

}  // namespace pdcg::dispersion
