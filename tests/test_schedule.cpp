#include <cmath>

#include <gtest/gtest.h>

#include "dynhet/schedule.hpp"

using namespace dynhet;

TEST(Schedule, LagsAreLogSpacedAndEndAtLagMax) {
  const auto lags = log_spaced_lags(0.1, 100.0, 8);
  ASSERT_EQ(lags.size(), 25u); // 3 decades x 8 + 1
  EXPECT_DOUBLE_EQ(lags.front(), 0.1);
  EXPECT_DOUBLE_EQ(lags.back(), 100.0);
  for (size_t j = 1; j < lags.size(); ++j) EXPECT_NEAR(std::log10(lags[j] / lags[j - 1]), 1.0 / 8, 1e-12);
  const auto odd = log_spaced_lags(1.0, 50.0, 4); // 50 is not on the grid: appended
  EXPECT_DOUBLE_EQ(odd.back(), 50.0);
  EXPECT_LT(odd[odd.size() - 2], 50.0);
}

TEST(Schedule, EveryPairAndOriginHasItsFrameAndNothingElseIsPublished) {
  ScheduleSpec spec{5, 2.0, 0.5, 8.0, 2, {}}; // lags 0.5 ... 8, origins every 2 (coinciding times)
  const auto s = make_schedule(spec, 10.0);
  for (size_t f = 1; f < s.frame_time.size(); ++f) EXPECT_GT(s.frame_time[f], s.frame_time[f - 1] + 1e-9);
  std::vector<bool> used(s.frame_time.size(), false);
  for (int k = 0; k < s.n_origins(); ++k) {
    const double t0 = 10.0 + 2.0 * k;
    EXPECT_NEAR(s.frame_time[s.origin_frame[k]], t0, 1e-12);
    used[s.origin_frame[k]] = true;
    for (int j = 0; j < s.n_lags(); ++j) {
      EXPECT_NEAR(s.frame_time[s.pair(k, j)], t0 + s.lag_time[j], 1e-9);
      used[s.pair(k, j)] = true;
    }
  }
  for (size_t f = 0; f < used.size(); ++f) EXPECT_TRUE(used[f]) << "frame " << f << " serves nothing";
  // Lag 2 and 8 of one origin meet other origins' times: fewer frames than pairs.
  EXPECT_LT(s.frame_time.size(), size_t(s.n_origins()) * (s.n_lags() + 1));
}

// An extra lag (a tau_alpha estimate) joins the log-spaced lags in order,
// and every origin gets a frame at it; one equal to a log-spaced lag adds
// nothing.
TEST(Schedule, ExtraLagsJoinTheLogSpacedOnes) {
  ScheduleSpec spec{3, 10.0, 1.0, 100.0, 1, {4.2, 10.0}};
  const FrameSchedule s = make_schedule(spec, 0.0);
  EXPECT_EQ(s.lag_time, (std::vector<double>{1.0, 4.2, 10.0, 100.0}));
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(s.frame_time[s.pair(k, 1)], 10.0 * k + 4.2);
}
