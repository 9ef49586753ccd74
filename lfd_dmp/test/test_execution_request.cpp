// Checks of an execution request: bounds named in their refusals, quaternions normalized
// within a tolerance and refused beyond, non-finite and out-of-workspace poses refused.
#include "lfd_dmp/execution_request.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

using lfd_dmp::RequestLimits;

std::string refusal(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ExecutionRequest, DurationScaleIsBoundedByTheConfiguredLimits) {
  const RequestLimits l;
  EXPECT_EQ(lfd_dmp::checkedDurationScale(0.0, l), 1.0);  // unset: the learned pace
  EXPECT_EQ(lfd_dmp::checkedDurationScale(2.5, l), 2.5);
  // Regression: 1e-9 "succeeded" without moving; 1000 took 1.36 GB.
  for (double bad : {1e-9, 1000.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    const std::string m = refusal([&] { lfd_dmp::checkedDurationScale(bad, l); });
    EXPECT_NE(m.find("~limits/min_duration_scale"), std::string::npos) << bad << ": " << m;
  }
}

TEST(ExecutionRequest, QuaternionsAreNormalizedWithinTheToleranceAndRefusedBeyond) {
  const RequestLimits l;
  const Eigen::Vector3d p(0.5, -0.3, 0.9);
  const double c = std::cos(0.15), s = std::sin(0.15);
  const lfd::Pose ok = lfd_dmp::checkedPose(p, Eigen::Vector4d(c, 0, 0, s) * 1.005, "goal", l);
  EXPECT_NEAR(ok.orientation.norm(), 1.0, 1e-12);
  EXPECT_NEAR(ok.orientation.angularDistance(Eigen::Quaterniond(c, 0, 0, s)), 0.0, 1e-12);
  // Regression: 2 x a yaw of 0.3 was planned at 0.96 rad; a zero quaternion was read as yaw 0.
  std::string m =
      refusal([&] { lfd_dmp::checkedPose(p, Eigen::Vector4d(2 * c, 0, 0, 2 * s), "goal", l); });
  EXPECT_NE(m.find("norm 2"), std::string::npos) << m;
  EXPECT_NE(m.find("~limits/quaternion_tolerance"), std::string::npos) << m;
  m = refusal([&] { lfd_dmp::checkedPose(p, Eigen::Vector4d::Zero(), "goal", l); });
  EXPECT_NE(m.find("zero quaternion"), std::string::npos) << m;
  m = refusal([&] {
    lfd_dmp::checkedPose(Eigen::Vector3d(std::nan(""), 0, 0), Eigen::Vector4d(1, 0, 0, 0),
                         "object 'box'", l);
  });
  EXPECT_NE(m.find("object 'box' has a NaN"), std::string::npos) << m;
  m = refusal([&] {
    lfd_dmp::checkedPose(p, Eigen::Vector4d(1, 0, std::numeric_limits<double>::infinity(), 0),
                         "goal", l);
  });
  EXPECT_FALSE(m.empty());
}

TEST(ExecutionRequest, PosesOutsideTheWorkspaceAndBadNamesAreRefused) {
  const RequestLimits l;
  lfd::Pose far;
  far.position = Eigen::Vector3d(1e11, 0, 0);
  const std::string m = refusal([&] { lfd_dmp::checkInWorkspace(far, "goal", l); });
  EXPECT_NE(m.find("~limits/workspace_max"), std::string::npos) << m;
  lfd::Pose near;
  near.position = Eigen::Vector3d(0.5, -0.3, 0.0);
  EXPECT_NO_THROW(lfd_dmp::checkInWorkspace(near, "goal", l));
  EXPECT_NE(refusal([&] {
              lfd_dmp::checkObjectNames({"box", "box"}, 2, l);
            }).find("twice"),
            std::string::npos);
  EXPECT_NE(refusal([&] { lfd_dmp::checkObjectNames({""}, 1, l); }).find("empty"),
            std::string::npos);
  EXPECT_NE(refusal([&] { lfd_dmp::checkObjectNames({"box"}, 2, l); }).find("1 object names"),
            std::string::npos);
  EXPECT_NE(refusal([&] {
              lfd_dmp::checkObjectNames(std::vector<std::string>(40, "x"), 40, l);
            }).find("~limits/max_objects"),
            std::string::npos);
  const std::string long_name(100000, 'a');
  const std::string n = refusal([&] { lfd_dmp::checkObjectNames({long_name}, 1, l); });
  EXPECT_NE(n.find("~limits/max_name_length"), std::string::npos);
  EXPECT_LT(n.size(), 300u);  // the name is clipped in the message
  EXPECT_NO_THROW(lfd_dmp::checkObjectNames({"stick", "box"}, 2, l));
}

TEST(ExecutionRequest, BadLimitSetsAreRefused) {
  RequestLimits l;
  EXPECT_NO_THROW(lfd_dmp::checkLimits(l));
  l.min_duration_scale = 0.0;
  EXPECT_THROW(lfd_dmp::checkLimits(l), std::invalid_argument);
  l = RequestLimits();
  l.workspace_min.x() = 5.0;
  EXPECT_THROW(lfd_dmp::checkLimits(l), std::invalid_argument);
  l = RequestLimits();
  l.max_plan_seconds = std::numeric_limits<double>::infinity();
  EXPECT_THROW(lfd_dmp::checkLimits(l), std::invalid_argument);
}

}  // namespace
