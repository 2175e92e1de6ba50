/// Test-only helpers: an embedded LAMMPS instance (C library API) used as the
/// independent reference for the readers, and a scratch directory.
#pragma once

#include <gtest/gtest.h>
#include <library.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "scratch_dir.hpp"

namespace pdcg::test {

class Lammps {
 public:
  Lammps() {
    const char* args[] = {"pdcg_test", "-log", "none", "-screen", "none", "-nocite"};
    h_ = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
  }
  ~Lammps() {
    if (h_) lammps_close(h_);
  }
  Lammps(const Lammps&) = delete;
  Lammps& operator=(const Lammps&) = delete;
  void* handle() const { return h_; }

  /// Runs commands (newline separated); fails the test on a LAMMPS error.
  void run(const std::string& commands) {
    lammps_commands_string(h_, commands.c_str());
    if (lammps_has_error(h_)) {
      char buf[1024];
      lammps_get_last_error_message(h_, buf, sizeof buf);
      ADD_FAILURE() << "LAMMPS error: " << buf << "\nwhile running:\n" << commands;
      throw std::runtime_error(buf);
    }
  }

  std::size_t natoms() const { return static_cast<std::size_t>(lammps_get_natoms(h_)); }

  /// Per-atom property ordered by atom id 1..N (ids must be contiguous).
  std::vector<double> gather_double(const char* name, int count) const {
    std::vector<double> out(natoms() * static_cast<std::size_t>(count));
    lammps_gather_atoms(h_, const_cast<char*>(name), 1, count, out.data());
    return out;
  }
  std::vector<int> gather_int(const char* name, int count) const {
    std::vector<int> out(natoms() * static_cast<std::size_t>(count));
    lammps_gather_atoms(h_, const_cast<char*>(name), 0, count, out.data());
    return out;
  }

  struct BoxData {
    Eigen::Vector3d lo, hi;
    double xy = 0, xz = 0, yz = 0;
    int periodic[3] = {1, 1, 1};
    Eigen::Matrix3d h() const {
      Eigen::Matrix3d m;
      m << hi.x() - lo.x(), xy, xz, 0, hi.y() - lo.y(), yz, 0, 0, hi.z() - lo.z();
      return m;
    }
  };
  BoxData box() const {
    BoxData b;
    double lo[3], hi[3];
    int boxflag = 0;
    lammps_extract_box(h_, lo, hi, &b.xy, &b.yz, &b.xz, b.periodic, &boxflag);
    b.lo = {lo[0], lo[1], lo[2]};
    b.hi = {hi[0], hi[1], hi[2]};
    return b;
  }

  /// Unwrapped positions x + H·image, 3N ordered by id, from LAMMPS's own x and image.
  std::vector<double> unwrapped_positions() const {
    const auto x = gather_double("x", 3);
    const auto img = gather_int("image", 3);  // count 3 unpacks the image flags
    const Eigen::Matrix3d H = box().h();
    std::vector<double> u(x.size());
    for (std::size_t i = 0; i < natoms(); ++i) {
      const Eigen::Vector3d xi(x[3 * i], x[3 * i + 1], x[3 * i + 2]);
      const Eigen::Vector3d m(img[3 * i], img[3 * i + 1], img[3 * i + 2]);
      const Eigen::Vector3d ui = xi + H * m;
      for (int k = 0; k < 3; ++k) u[3 * i + static_cast<std::size_t>(k)] = ui[k];
    }
    return u;
  }

 private:
  void* h_ = nullptr;
};

}  // namespace pdcg::test
