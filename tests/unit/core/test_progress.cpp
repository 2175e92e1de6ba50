#include <gtest/gtest.h>

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
