// Frame selection and reading of configurations (atomistic/configurations.hpp), the library
// functions behind `--frame`/`--frames` of the CLI and `frame=`/`frames=` of the Python module.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>

#include "pdcg/atomistic/configurations.hpp"
#include "pdcg/core/error.hpp"
#include "scratch_dir.hpp"

using namespace pdcg;
using namespace pdcg::atomistic;

namespace {

void write_dump(const std::string& path, int frames) {
  std::ofstream f(path);
  for (int s = 0; s < frames; ++s)
    f << "ITEM: TIMESTEP\n"
      << 10 * s << "\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n"
      << "0 4\n0 4\n0 4\nITEM: ATOMS id type x y z\n2 1 2.0 1.0 1.0\n1 1 1.0 1.0 1.0\n";
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(Configurations, SelectFramesLikePython) {
  // one frame, negative from the end; A:B[:S] with B inclusive; neither = frame 0
  auto r = select_frames(-1, "", 5, "d");
  EXPECT_EQ(r.first, 4);
  EXPECT_EQ(r.last, 5);
  r = select_frames(std::nullopt, "1:3", 5, "d");
  EXPECT_EQ(r.first, 1);
  EXPECT_EQ(r.last, 4);
  EXPECT_EQ(r.step, 1);
  r = select_frames(std::nullopt, "0:4:2", 5, "d");
  EXPECT_EQ(r.last, 5);
  EXPECT_EQ(r.step, 2);
  r = select_frames(std::nullopt, "", 5, "d");
  EXPECT_EQ(r.first, 0);
  EXPECT_EQ(r.last, 1);
}

TEST(Configurations, MessagesNameTheCallersOptions) {
  const std::string cli = message_of([] { (void)select_frames(7, "", 5, "d.lammpstrj"); });
  EXPECT_EQ(cli,
            "d.lammpstrj: --frame: frame range out of bounds: got '7', expected frames within "
            "0..4 (the file holds 5 frames). Fix: count frames from 0; negative numbers count "
            "from the end");
  const std::string py = message_of([] {
    (void)select_frames(7, "", 5, "d.lammpstrj", {"frame", "frames"});
  });
  EXPECT_NE(py.find("d.lammpstrj: frame: frame range out of bounds"), std::string::npos) << py;
  EXPECT_NE(message_of([] {
              (void)select_frames(1, "0:1", 5, "d");
            }).find("give one of --frame and --frames"),
            std::string::npos);
}

TEST(Configurations, ReadsDumpFramesSortedAndDataFiles) {
  test::ScratchDir dir("configurations");
  write_dump(dir / "d.lammpstrj", 3);
  std::string units = "stale";
  auto frames = read_configurations(dir / "d.lammpstrj", std::nullopt, "1:2", &units);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].timestep, 10);
  EXPECT_EQ(frames[1].timestep, 20);
  EXPECT_EQ(frames[0].id, (std::vector<std::int64_t>{1, 2}));  // sorted by id
  EXPECT_EQ(units, "");                                        // the dump has no ITEM: UNITS
  auto last = read_configurations(dir / "d.lammpstrj", -1, "", nullptr);
  EXPECT_EQ(last.at(0).timestep, 20);
  {
    std::ofstream f(dir / "c.data");
    f << "title\n\n2 atoms\n1 atom types\n0 4 xlo xhi\n0 4 ylo yhi\n0 4 zlo zhi\n\nMasses\n\n1 "
         "1.0\n\n"
         "Atoms # atomic\n\n1 1 1.0 1.0 1.0\n2 1 2.0 1.0 1.0\n";
  }
  EXPECT_EQ(read_configurations(dir / "c.data", -1, "", &units).at(0).size(), 2u);
  EXPECT_NE(message_of([&] {
              (void)read_configurations(dir / "c.data", 1, "", nullptr);
            }).find("the file holds 1 frame)"),
            std::string::npos);
}
