// The shared timestamp policy: stamp order, out-of-order, duplicate and gap
// counts.
#include "lfd_core/io/stamp_order.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace {

TEST(StampOrder, OneLateMessageIsMovedAndCountedOnce) {
  const std::vector<double> stamps = {0.0, 0.1, 0.75, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8};
  lfd::StampReport r;
  const std::vector<std::size_t> order =
      lfd::orderByStamp(stamps, lfd::DuplicateStamps::kKeepFirst, &r);
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 3, 4, 5, 6, 7, 8, 2, 9}));
  EXPECT_EQ(r.out_of_order, 1u);  // not the seven stamped before it
  EXPECT_EQ(r.duplicates, 0u);
  EXPECT_EQ(lfd::stampWarning("/ee_pose", r),
            "/ee_pose: of 10 messages, 1 stamped out of order (put in order)");
}

TEST(StampOrder, DuplicatesAreKeptOrLeftOutButAlwaysCounted) {
  const std::vector<double> stamps = {0.0, 0.1, 0.1, 0.2};
  lfd::StampReport all, first;
  EXPECT_EQ(lfd::orderByStamp(stamps, lfd::DuplicateStamps::kKeepAll, &all).size(), 4u);
  EXPECT_EQ(lfd::orderByStamp(stamps, lfd::DuplicateStamps::kKeepFirst, &first),
            (std::vector<std::size_t>{0, 1, 3}));
  EXPECT_EQ(all.duplicates, 1u);
  EXPECT_EQ(all.dropped, 0u);
  EXPECT_EQ(first.dropped, 1u);
  EXPECT_NE(
      lfd::stampWarning("/t", first).find("1 with a duplicate stamp (the first of each kept)"),
      std::string::npos);
}

TEST(StampOrder, GapsAreReportedAndARegularClockSaysNothing) {
  std::vector<double> stamps;
  for (int i = 0; i < 100; ++i) stamps.push_back(0.01 * i);
  lfd::StampReport r;
  lfd::orderByStamp(stamps, lfd::DuplicateStamps::kKeepAll, &r);
  EXPECT_EQ(lfd::stampWarning("/t", r), "");
  for (double& t : stamps) t += t > 0.5 ? 0.3 : 0.0;  // 0.3 s missing after 0.5 s
  lfd::orderByStamp(stamps, lfd::DuplicateStamps::kKeepAll, &r);
  EXPECT_NEAR(r.largest_gap, 0.31, 1e-9);
  EXPECT_NEAR(r.gap_start, 0.5, 1e-9);
  EXPECT_NE(lfd::stampWarning("/t", r).find("a gap of 0.31 s at t = 0.5"), std::string::npos);
}

}  // namespace
