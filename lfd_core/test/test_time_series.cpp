// Resampling onto one clock: a stream faster than the clock is averaged over each period, a
// stream at or below it interpolated, a discrete one held.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lfd_core/segmentation/time_series.hpp"

namespace {

// A stream of a unit step at `step_at` plus noise, sampled at `rate` from `start` s on.
lfd::Stream sampled(double rate, double seconds, double noise, double step_at, unsigned seed,
                    lfd::Interpolation interpolation = lfd::Interpolation::kLinear,
                    double start = 0.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, noise);
  lfd::Stream s{"x", {}, {}, interpolation};
  for (int k = 0; k <= static_cast<int>(std::lround(seconds * rate)); ++k) {
    const double t = start + k / rate;
    s.time.push_back(t);
    s.values.push_back((t >= step_at ? 1.0 : 0.0) + (noise > 0.0 ? g(rng) : 0.0));
  }
  return s;
}

double sigma(const Eigen::VectorXd& x) {
  return std::sqrt((x.array() - x.mean()).square().mean());
}

// The clock of these tests: a 50 Hz stream from 0 s. A 200 Hz stream from -1.2 ms has no sample
// on a period's edge (k / 50 s +- 10 ms).
lfd::Stream clockStream(double seconds) {
  return sampled(50.0, seconds, 0.0, 1e9, 0);
}
constexpr double kOffGrid = -0.0012;

// A 200 Hz noisy sensor read at 50 Hz: each row is the mean of the four samples of its period,
// so the noise drops to half (a point reading keeps all of it and drops three samples in four).
TEST(Resample, AStreamFasterThanTheClockIsAveragedOverEachPeriod) {
  const lfd::Stream s = sampled(200.0, 20.0, 1.0, 1e9, 3, lfd::Interpolation::kLinear, kOffGrid);
  const lfd::FeatureMatrix m = lfd::resample({clockStream(19.9), s}, 50.0);
  ASSERT_EQ(m.rows(), 996);
  EXPECT_NEAR(sigma(m.data.col(1)), 0.5, 0.05);
  // Row 1 (20 ms) averages the samples within 10..30 ms: 13.8, 18.8, 23.8 and 28.8 ms.
  EXPECT_NEAR(m.data(1, 1), (s.values[3] + s.values[4] + s.values[5] + s.values[6]) / 4.0, 1e-12);
}

// The average is centred on the row: a step stays where it was (within half a period), and a
// noise-free stream at or below the clock's rate is interpolated exactly as before.
TEST(Resample, AveragingKeepsStepsInPlaceAndSlowerStreamsAreInterpolated) {
  const lfd::FeatureMatrix fast = lfd::resample(
      {clockStream(3.9), sampled(200.0, 4.0, 0.0, 2.0, 1, lfd::Interpolation::kLinear, kOffGrid)},
      50.0);
  EXPECT_DOUBLE_EQ(fast.data(99, 1), 0.0);   // 1.98 s: 1.9738 .. 1.9888 s
  EXPECT_DOUBLE_EQ(fast.data(100, 1), 0.5);  // 2.00 s: two samples before the step, two after
  EXPECT_DOUBLE_EQ(fast.data(101, 1), 1.0);
  const lfd::Stream slow = sampled(40.0, 4.0, 0.3, 2.0, 2);
  const lfd::FeatureMatrix m = lfd::resample({slow}, 50.0);
  const std::vector<double> expected = lfd::interpolate(slow, m.time);
  for (Eigen::Index r = 0; r < m.rows(); ++r) EXPECT_DOUBLE_EQ(m.data(r, 0), expected[r]) << r;
}

// A discrete stream (flags, commands) is never averaged: a mean of two states is no state.
TEST(Resample, DiscreteStreamsAreHeldNotAveraged) {
  const lfd::FeatureMatrix m =
      lfd::resample({sampled(200.0, 4.0, 0.0, 2.0, 1, lfd::Interpolation::kZeroOrderHold)}, 50.0);
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    EXPECT_TRUE(m.data(r, 0) == 0.0 || m.data(r, 0) == 1.0) << r;
}

// A matrix on its own clock (a CSV at 1 kHz) goes onto a 100 Hz clock column by column, each
// averaged over the period: a line stays the line (within half an input sample: the period holds
// ten of its samples), the names stay. No clock, no resampling.
TEST(Resample, AMatrixOnItsOwnClockIsResampledColumnByColumn) {
  lfd::FeatureMatrix m;
  m.names = {"up", "down"};
  m.data.resize(2001, 2);
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    m.time.push_back(0.001 * static_cast<double>(r));
    m.data(r, 0) = m.time.back();
    m.data(r, 1) = -2.0 * m.time.back();
  }
  const lfd::FeatureMatrix out = lfd::resample(m, 100.0);
  ASSERT_EQ(out.rows(), 201);
  EXPECT_EQ(out.names, m.names);
  for (Eigen::Index r = 1; r + 1 < out.rows(); ++r) {
    EXPECT_NEAR(out.data(r, 0), out.time[static_cast<std::size_t>(r)], 0.5e-3 + 1e-9) << r;
    EXPECT_NEAR(out.data(r, 1), -2.0 * out.time[static_cast<std::size_t>(r)], 1e-3 + 1e-9) << r;
  }
  m.time.clear();
  EXPECT_THROW(lfd::resample(m, 100.0), std::invalid_argument);
}

}  // namespace
