// Large DMP fits: the learner accepts up to 1000 basis functions (learner.yaml
// limits/max_num_basis), and a fit with a few hundred exercises Eigen's blocked LDLT kernels,
// which crashed (an AVX store into a 16-byte aligned buffer) while the build mixed -march=native
// with pinned Eigen alignment. The fit must stay finite and reproduce the demo at least as well
// as the default 50 basis functions.
#include "dmp_test_curves.hpp"
#include "lfd_core/dmp/position_dmp.hpp"

#include <gtest/gtest.h>

namespace {

constexpr double kDuration = 2.0;
constexpr int kSamples = 2000;

double reproductionErrorPercent(int num_basis, Eigen::MatrixXd* weights = nullptr) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(kSamples, 0.0, kDuration);
  const Eigen::MatrixXd demo = lfd_test::curve3d(t, kDuration);
  lfd::DmpParameters params;
  params.num_basis = num_basis;
  const lfd::PositionDmp dmp = lfd::PositionDmp::learn(t, demo, params);
  if (weights) *weights = dmp.weights();
  lfd::PositionRolloutOptions o;
  o.dt = t[1] - t[0];
  const auto traj = dmp.rollout(o);
  EXPECT_TRUE(traj.positions.allFinite());
  return 100.0 * lfd_test::rmse(traj.positions, demo) / lfd_test::extent(demo);
}

class ManyBasisFunctions : public ::testing::TestWithParam<int> {};

TEST_P(ManyBasisFunctions, FitIsFiniteAndReproducesTheDemo) {
  Eigen::MatrixXd weights;
  const double pct = reproductionErrorPercent(GetParam(), &weights);
  ASSERT_EQ(weights.rows(), GetParam());
  EXPECT_TRUE(weights.allFinite());
  // Far below the skill library's plausibility bound on stored weights (1e9).
  EXPECT_LT(weights.cwiseAbs().maxCoeff(), 1e6);
  EXPECT_LT(pct, 0.1);
  EXPECT_LE(pct, reproductionErrorPercent(50) * 1.5);
}

INSTANTIATE_TEST_SUITE_P(Large, ManyBasisFunctions, ::testing::Values(300, 1000));

}  // namespace
