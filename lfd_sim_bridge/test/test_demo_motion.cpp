// Unit tests of the demonstrator's motion primitives: minimum-jerk time law, pose interpolation
// and the band-limited tremor (its amplitude and its frequency band).
#include <cmath>
#include <complex>
#include <vector>

#include <gtest/gtest.h>

#include "lfd_sim_bridge/demo_motion.hpp"

using lfd_sim_bridge::demo::interpolate;
using lfd_sim_bridge::demo::minJerk;
using lfd_sim_bridge::demo::minJerkRate;
using lfd_sim_bridge::demo::Pose;
using lfd_sim_bridge::demo::Tremor;

TEST(MinJerk, BoundaryValuesAndSymmetry) {
  EXPECT_DOUBLE_EQ(minJerk(0.0), 0.0);
  EXPECT_DOUBLE_EQ(minJerk(1.0), 1.0);
  EXPECT_NEAR(minJerk(0.5), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(minJerk(-0.3), 0.0);  // clamped outside [0, 1]
  EXPECT_DOUBLE_EQ(minJerk(1.7), 1.0);
  for (double u = 0.05; u < 1.0; u += 0.05) EXPECT_NEAR(minJerk(u) + minJerk(1.0 - u), 1.0, 1e-12);
}

TEST(MinJerk, MonotoneWithZeroEndVelocityAndAcceleration) {
  double previous = 0.0;
  for (int k = 1; k <= 1000; ++k) {
    const double s = minJerk(k / 1000.0);
    EXPECT_GT(s, previous);
    previous = s;
  }
  const double h = 1e-4;
  EXPECT_NEAR(minJerk(h) / h, 0.0, 1e-6);                // velocity ~ 0 at the start
  EXPECT_NEAR((1.0 - minJerk(1.0 - h)) / h, 0.0, 1e-6);  // and at the end
  const double accel0 = (minJerk(2 * h) - 2 * minJerk(h) + minJerk(0)) / (h * h);
  EXPECT_NEAR(accel0, 0.0, 1e-2);
}

TEST(MinJerk, RateMatchesNumericalDerivative) {
  for (double u = 0.01; u < 1.0; u += 0.07) {
    const double h = 1e-6;
    EXPECT_NEAR(minJerkRate(u), (minJerk(u + h) - minJerk(u - h)) / (2 * h), 1e-6);
  }
  EXPECT_NEAR(minJerkRate(0.5), 1.875, 1e-12);
  EXPECT_DOUBLE_EQ(minJerkRate(0.0), 0.0);
  EXPECT_DOUBLE_EQ(minJerkRate(1.0), 0.0);
}

TEST(Interpolate, EndpointsAndMidpoint) {
  Pose a, b;
  a.position = {0.1, -0.2, 0.3};
  b.position = {0.5, 0.2, 0.1};
  b.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(interpolate(a, b, 0.0).position.isApprox(a.position));
  EXPECT_TRUE(interpolate(a, b, 1.0).position.isApprox(b.position));
  EXPECT_NEAR(interpolate(a, b, 1.0).orientation.angularDistance(b.orientation), 0.0, 1e-9);
  const Pose mid = interpolate(a, b, 0.5);
  EXPECT_TRUE(mid.position.isApprox(Eigen::Vector3d(0.3, 0.0, 0.2)));
  EXPECT_NEAR(mid.orientation.angularDistance(a.orientation), M_PI / 4, 1e-9);
}

// Power of x (sampled at fs) in [lo, hi] Hz by a plain DFT over the whole window.
double bandPower(const std::vector<double>& x, double fs, double lo, double hi) {
  const size_t n = x.size();
  double power = 0.0;
  for (size_t k = 1; k < n / 2; ++k) {
    const double f = k * fs / n;
    if (f < lo || f > hi) continue;
    std::complex<double> sum = 0.0;
    for (size_t i = 0; i < n; ++i) sum += x[i] * std::polar(1.0, -2.0 * M_PI * k * i / n);
    power += std::norm(sum);
  }
  return power;
}

TEST(Tremor, AmplitudeMatchesRequestedRms) {
  const Tremor tremor(0.002, 8.0, 12.0, 42);
  double sum_sq[3] = {0, 0, 0};
  double peak = 0.0;
  const int n = 40000;  // 40 s at 1 kHz
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d v = tremor.at(i * 1e-3);
    for (int k = 0; k < 3; ++k) sum_sq[k] += v[k] * v[k];
    peak = std::max(peak, v.cwiseAbs().maxCoeff());
  }
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::sqrt(sum_sq[k] / n), 0.002, 0.0004) << "axis " << k;
  EXPECT_LT(peak, 0.012);  // a few millimetres, never centimetres
}

TEST(Tremor, EnergyIsInTheRequestedBand) {
  const Tremor tremor(0.002, 8.0, 12.0, 7);
  const double fs = 200.0;
  std::vector<double> x(2000);  // 10 s
  for (size_t i = 0; i < x.size(); ++i) x[i] = tremor.at(i / fs).y();
  const double total = bandPower(x, fs, 0.0, fs / 2);
  const double in_band = bandPower(x, fs, 7.5, 12.5);
  const double slow = bandPower(x, fs, 0.0, 5.0);
  EXPECT_GT(in_band / total, 0.95);
  EXPECT_LT(slow / total, 0.01);  // no drift: the commanded path's shape is preserved
}

TEST(Tremor, SeededAndZeroByDefault) {
  const Tremor a(0.002, 8.0, 12.0, 1), b(0.002, 8.0, 12.0, 1), c(0.002, 8.0, 12.0, 2);
  EXPECT_TRUE(a.at(0.37).isApprox(b.at(0.37)));
  EXPECT_FALSE(a.at(0.37).isApprox(c.at(0.37), 1e-3));
  EXPECT_TRUE(Tremor().at(1.23).isZero());
  EXPECT_THROW(Tremor(0.002, 12.0, 8.0, 1), std::invalid_argument);
  EXPECT_THROW(Tremor(-1.0, 8.0, 12.0, 1), std::invalid_argument);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
