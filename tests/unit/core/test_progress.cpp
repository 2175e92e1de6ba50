#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "pdcg/core/progress.hpp"

TEST(Progress, StatusShowsCountPercentAndEta) {
  pdcg::Progress p("steps", 100);
  p.set_terminal(false);
  const std::string s = p.status(40);
  EXPECT_NE(s.find("steps 40/100 (40%)"), std::string::npos) << s;
  EXPECT_NE(s.find("/s"), std::string::npos) << s;
  pdcg::Progress q("frames", 0);
  EXPECT_EQ(q.status(7).rfind("frames 7 ", 0), 0u) << q.status(7);
  p.finish();
}

TEST(Progress, LoopLeftEarlyNeverReadsComplete) {
  // A loop left by an exception after 3 of 10 steps: the last line shows 3/10 and "stopped",
  // not the total (the old destructor printed 10/10 (100%) for a failed run).
  testing::internal::CaptureStderr();
  try {
    pdcg::Progress p("steps", 10);
    p.set_terminal(false);
    p.update(3);
    throw std::runtime_error("step 4 failed");
  } catch (const std::runtime_error&) {
  }
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("steps 3/10 (30%)"), std::string::npos) << err;
  EXPECT_NE(err.find("stopped"), std::string::npos) << err;
  EXPECT_EQ(err.find("100%"), std::string::npos) << err;
  // 199 of 200 is 99 %, not a rounded 100 %
  pdcg::Progress q("steps", 200);
  EXPECT_NE(q.status(199).find("(99%)"), std::string::npos) << q.status(199);
  q.finish();
}

TEST(Progress, ObserverSeesEveryUpdateAndTheFinish) {
  // The hook of the Python module's progress callbacks: every update and the finish reach the
  // observer (label, done, total) before any throttling; an empty observer removes it.
  std::vector<std::tuple<std::string, std::uint64_t, std::uint64_t>> seen;
  pdcg::Progress::set_observer([&](const std::string& label, std::uint64_t done,
                                   std::uint64_t total) { seen.emplace_back(label, done, total); });
  {
    pdcg::Progress p("steps", 3, 1e9);
    p.set_terminal(false);
    p.update(1);
    p.update(2);
    p.finish();
  }
  pdcg::Progress::set_observer({});
  {
    pdcg::Progress q("frames", 2, 1e9);
    q.update(1);
    q.finish();
  }
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0], std::make_tuple(std::string("steps"), std::uint64_t{1}, std::uint64_t{3}));
  EXPECT_EQ(seen[1], std::make_tuple(std::string("steps"), std::uint64_t{2}, std::uint64_t{3}));
  EXPECT_EQ(seen[2], std::make_tuple(std::string("steps"), std::uint64_t{3}, std::uint64_t{3}));
}

TEST(Progress, ObserverExceptionLeavesTheLoop) {
  pdcg::Progress::set_observer([](const std::string&, std::uint64_t done, std::uint64_t) {
    if (done == 2) throw std::runtime_error("stop at 2");
  });
  int steps = 0;
  try {
    pdcg::Progress p("steps", 5, 1e9);
    for (int i = 1; i <= 5; ++i) {
      p.update(static_cast<std::uint64_t>(i));
      ++steps;
    }
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "stop at 2");
  }
  pdcg::Progress::set_observer({});
  EXPECT_EQ(steps, 1);
}
