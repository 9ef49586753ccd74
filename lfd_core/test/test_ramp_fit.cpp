// Flat-ramp-flat fit (ramp_fit.hpp): exact on clean steps and ramps, close on noisy ones, and a
// window too small is an error.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "lfd_core/segmentation/ramp_fit.hpp"

namespace {

std::vector<double> ramp(std::size_t n, std::size_t start, std::size_t end, double lo, double hi) {
  std::vector<double> y(n);
  for (std::size_t t = 0; t < n; ++t) {
    const double u =
        t < start  ? 0.0
        : t >= end ? 1.0
                   : static_cast<double>(t - start + 1) / static_cast<double>(end - start + 1);
    y[t] = lo + (hi - lo) * u;
  }
  return y;
}

TEST(RampFit, StepIsARampOfOneSample) {
  std::vector<double> y(100, 0.0);
  std::fill(y.begin() + 40, y.end(), 2.0);
  const lfd::RampFit f = lfd::fitRamp(y, 0, y.size());
  EXPECT_EQ(f.start, 40u);
  EXPECT_EQ(f.end, 40u);
  EXPECT_NEAR(f.before, 0.0, 1e-12);
  EXPECT_NEAR(f.after, 2.0, 1e-12);
}

TEST(RampFit, CleanRampStartAndEndExactlyWithinAWindow) {
  const std::vector<double> y = ramp(300, 120, 180, 1.0, -3.0);  // a falling ramp, absolute indices
  const lfd::RampFit f = lfd::fitRamp(y, 100, 220);
  EXPECT_EQ(f.start, 120u);
  EXPECT_EQ(f.end, 180u);
  EXPECT_NEAR(f.before, 1.0, 1e-9);
  EXPECT_NEAR(f.after, -3.0, 1e-9);
}

// A slow noisy force build-up (1 s at 50 Hz, noise a tenth of its height): the fit finds where it
// starts and ends within 0.1 s, where a threshold at 40 % of the height would be 0.4 s late.
TEST(RampFit, NoisyRampWithinAFewSamples) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> y = ramp(200, 80, 130, 0.0, 3.0);
    for (double& v : y) v += noise(rng);
    const lfd::RampFit f = lfd::fitRamp(y, 40, 170);
    EXPECT_NEAR(static_cast<double>(f.start), 80.0, 5.0) << trial;
    EXPECT_NEAR(static_cast<double>(f.end), 130.0, 5.0) << trial;
  }
}

TEST(RampFit, ConstantWindowAndBadWindows) {
  const std::vector<double> flat(10, 4.0);
  const lfd::RampFit f = lfd::fitRamp(flat, 2, 8);
  EXPECT_EQ(f.before, 4.0);
  EXPECT_EQ(f.after, 4.0);
  EXPECT_THROW(lfd::fitRamp(flat, 5, 6), std::invalid_argument);
  EXPECT_THROW(lfd::fitRamp(flat, 9, 20), std::invalid_argument);  // clipped to 1 sample
  EXPECT_THROW(lfd::fitRamp({}, 0, 5), std::invalid_argument);
}

}  // namespace
