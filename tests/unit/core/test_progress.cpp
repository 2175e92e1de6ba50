#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

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
