/// Benchmark (not a test): how fast DumpReader indexes and parses a LAMMPS text dump.
/// Usage: bench_parse_dump FILE
/// Prints one "key value" line per measurement (seconds, bytes), read by parse_dump.sh.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "pdcg/atomistic/dump_reader.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FILE\n", argv[0]);
    return 2;
  }
  using clock = std::chrono::steady_clock;
  const auto seconds = [](clock::time_point a, clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  };
  try {
    double checksum = 0.0;
    // What `DumpReader(path).frame(0)` costs: the index grows only to frame 0.
    const auto s0 = clock::now();
    {
      pdcg::atomistic::DumpReader first(argv[1]);
      const auto a = first.frame(0);
      checksum += a.x.empty() ? 0.0 : a.x[0];
    }
    const auto s1 = clock::now();
    const auto t0 = clock::now();
    pdcg::atomistic::DumpReader dump(argv[1]);
    (void)dump.nframes();  // the whole index
    const auto t1 = clock::now();
    {
      const auto a = dump.frame(0);
      checksum += a.x.empty() ? 0.0 : a.x[0];
    }
    const auto t2 = clock::now();
    {
      const auto a = dump.last();
      checksum += a.x.empty() ? 0.0 : a.x[0];
    }
    const auto t3 = clock::now();
    std::size_t atoms = 0;
    for (std::size_t n = 0; n < dump.nframes(); ++n) {
      const auto a = dump.frame(n);
      atoms += a.size();
      checksum += a.x.empty() ? 0.0 : a.x[a.x.size() / 2];
    }
    const auto t4 = clock::now();
    const auto& f0 = dump.info(0);
    const std::uint64_t frame0_bytes =
        dump.nframes() > 1 ? dump.info(1).offset - f0.offset : std::filesystem::file_size(argv[1]);
    std::printf("file_bytes %ju\n",
                static_cast<std::uintmax_t>(std::filesystem::file_size(argv[1])));
    std::printf("frames %zu\natoms_total %zu\nframe0_bytes %ju\n", dump.nframes(), atoms,
                static_cast<std::uintmax_t>(frame0_bytes));
    std::printf("open_frame0_seconds %.4f\n", seconds(s0, s1));
    std::printf("index_seconds %.4f\nframe0_seconds %.4f\nlast_seconds %.4f\nall_seconds %.4f\n",
                seconds(t0, t1), seconds(t1, t2), seconds(t2, t3), seconds(t3, t4));
    std::printf("checksum %.6g\n", checksum);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_parse_dump: %s\n", e.what());
    return 2;
  }
  return 0;
}
