// The executor's plan as ROS messages: poses through the suite's one pose conversion.
#include "lfd_dmp/plan_messages.hpp"

#include <gtest/gtest.h>

namespace {

lfd::Pose pose(double x, double y, double z, const Eigen::Quaterniond& q) {
  lfd::Pose p;
  p.position = Eigen::Vector3d(x, y, z);
  p.orientation = q;
  return p;
}

TEST(PlanMessages, PoseMessageCopiesPositionAndQuaternion) {
  // Not normalized and w < 0 on purpose: the conversion copies, it does not fix a quaternion.
  const lfd::Pose p = pose(0.1, -0.25, 1.0 / 3.0, Eigen::Quaterniond(-0.5, 0.1, 0.2, 0.3));
  const geometry_msgs::Pose m = lfd_dmp::toPoseMsg(p);
  EXPECT_EQ(m.position.x, 0.1);
  EXPECT_EQ(m.position.y, -0.25);
  EXPECT_EQ(m.position.z, 1.0 / 3.0);
  EXPECT_EQ(m.orientation.w, -0.5);
  EXPECT_EQ(m.orientation.x, 0.1);
  EXPECT_EQ(m.orientation.y, 0.2);
  EXPECT_EQ(m.orientation.z, 0.3);
  EXPECT_EQ(lfd_msgs::toPoseMsg(p), m);  // the same conversion, under the message package's name
}

TEST(PlanMessages, PathAndMarkersCarryThePlannedPoses) {
  lfd_dmp::ExecutionPlan plan;
  for (int k = 0; k < 12; ++k)
    plan.poses.push_back(pose(0.01 * k, 0.0, 1.0, Eigen::Quaterniond(0.0, 1.0, 0.0, 0.0)));
  lfd_dmp::PlannedSegment s;
  s.name = "reach";
  s.begin = 2;
  s.goal = pose(0.3, 0.2, 0.9, Eigen::Quaterniond::Identity());
  plan.segments.push_back(s);
  const nav_msgs::Path path = lfd_dmp::plannedPath(plan, "base_link", ros::Time(5.0));
  ASSERT_EQ(path.poses.size(), 2u);  // every 10th sample
  EXPECT_EQ(path.poses[1].pose, lfd_dmp::toPoseMsg(plan.poses[10]));
  EXPECT_EQ(path.poses[1].header.frame_id, "base_link");
  const visualization_msgs::MarkerArray markers =
      lfd_dmp::segmentMarkers(plan, "base_link", ros::Time(5.0));
  ASSERT_EQ(markers.markers.size(), 4u);  // clear, then goal, label and start of the segment
  EXPECT_EQ(markers.markers[1].pose, lfd_dmp::toPoseMsg(s.goal));
  EXPECT_EQ(markers.markers[3].pose, lfd_dmp::toPoseMsg(plan.poses[2]));
}

}  // namespace
