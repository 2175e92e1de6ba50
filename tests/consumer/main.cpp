// Uses the installed pdcg: version, an error, and an atomic HDF5 round trip.
#include <pdcg/core/error.hpp>
#include <pdcg/core/version.hpp>
#include <pdcg/io/hdf5.hpp>

#include <cstdio>
#include <filesystem>
#include <vector>

int main() {
  std::printf("consumer: pdcg %s\n", pdcg::version().c_str());
  const auto path = std::filesystem::temp_directory_path() / "pdcg_consumer.h5";
  {
    pdcg::io::H5Writer w(path, {"pdcg-consumer", 1, pdcg::UnitStyle::lj, "", "consumer"});
    const std::vector<double> x{1.0, 2.0};
    w.write("x", x);
    w.commit();
  }
  pdcg::io::H5Reader r(path);
  const bool ok = r.read_double("x")[1] == 2.0 && r.info().format == "pdcg-consumer";
  std::filesystem::remove(path);
  std::printf("%s\n", ok ? "round trip ok" : "round trip FAILED");
  return ok ? 0 : 1;
}
