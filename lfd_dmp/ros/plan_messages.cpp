#include "lfd_dmp/plan_messages.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {

trajectory_msgs::JointTrajectory toJointTrajectory(const ExecutionPlan& plan,
                                                   const ros::Time& start, double period,
                                                   size_t from) {
  trajectory_msgs::JointTrajectory msg;
  const size_t n = plan.times.size();
  if (from >= n && n > 0) throw std::invalid_argument("toJointTrajectory: no sample from there");
  const double offset = n > 0 ? plan.times[from] : 0.0;
  msg.header.stamp = start + ros::Duration(offset);
  msg.joint_names = plan.joint_names;
  const size_t every = std::max<size_t>(1, static_cast<size_t>(std::lround(period / plan.dt)));
  std::vector<size_t> knots;
  for (size_t k = from; k < n; k += every) knots.push_back(k);
  if (n > 0 && knots.back() != n - 1) knots.push_back(n - 1);
  for (size_t k : knots) {
    trajectory_msgs::JointTrajectoryPoint p;
    p.time_from_start = ros::Duration(plan.times[k] - offset);
    const Eigen::VectorXd& q = plan.joints[k];
    p.positions.assign(q.data(), q.data() + q.size());
    // Central differences (one-sided at the start; zero at the last sample: the arm stops there).
    Eigen::VectorXd v = Eigen::VectorXd::Zero(q.size());
    if (k + 1 < n) {
      const size_t a = k > 0 ? k - 1 : k;
      v = (plan.joints[k + 1] - plan.joints[a]) / (plan.times[k + 1] - plan.times[a]);
    }
    p.velocities.assign(v.data(), v.data() + v.size());
    msg.points.push_back(std::move(p));
  }
  return msg;
}

void checkTrajectoryVelocities(const trajectory_msgs::JointTrajectory& trajectory,
                               const std::vector<std::string>& joint_names,
                               const Eigen::VectorXd& limits) {
  std::vector<double> limit(trajectory.joint_names.size(), 0.0);
  for (size_t j = 0; j < limit.size(); ++j) {
    const auto it = std::find(joint_names.begin(), joint_names.end(), trajectory.joint_names[j]);
    const auto k = static_cast<Eigen::Index>(it - joint_names.begin());
    if (it != joint_names.end() && k < limits.size()) limit[j] = limits[k];
  }
  for (const trajectory_msgs::JointTrajectoryPoint& p : trajectory.points) {
    for (size_t j = 0; j < p.velocities.size() && j < limit.size(); ++j) {
      if (!(limit[j] > 0.0) || !std::isfinite(limit[j]) || std::abs(p.velocities[j]) <= limit[j])
        continue;
      std::ostringstream msg;
      msg << "the planned motion moves joint " << trajectory.joint_names[j] << " at "
          << std::abs(p.velocities[j]) << " rad/s at t = " << p.time_from_start.toSec()
          << " s, over its velocity limit of " << limit[j]
          << " rad/s (the robot's URDF): the driver would refuse it; a larger duration_scale "
             "plans it slower";
      throw std::invalid_argument(msg.str());
    }
  }
}

trajectory_msgs::JointTrajectory holdTrajectory(const std::vector<std::string>& joints,
                                                const Eigen::VectorXd& q, const ros::Time& stamp) {
  trajectory_msgs::JointTrajectory msg;
  msg.header.stamp = stamp;
  msg.joint_names = joints;
  trajectory_msgs::JointTrajectoryPoint p;
  p.time_from_start = ros::Duration(0.0);
  p.positions.assign(q.data(), q.data() + q.size());
  msg.points.push_back(p);
  return msg;
}

lfd_msgs::GripperCommand gripperCommand(bool close, const lfd::GripperSetup& gripper,
                                        const ros::Time& stamp) {
  lfd_msgs::GripperCommand g;
  g.header.stamp = stamp;
  g.position = close ? gripper.close_opening : gripper.open_opening;
  g.max_effort = close ? gripper.close_effort : 0.0;
  return g;
}

nav_msgs::Path plannedPath(const ExecutionPlan& plan, const std::string& frame,
                           const ros::Time& stamp) {
  nav_msgs::Path path;
  path.header.frame_id = frame;
  path.header.stamp = stamp;
  for (size_t k = 0; k < plan.poses.size(); k += 10) {  // every 10th sample is plenty for rviz
    geometry_msgs::PoseStamped ps;
    ps.header = path.header;
    ps.pose = toPoseMsg(plan.poses[k]);
    path.poses.push_back(ps);
  }
  return path;
}

visualization_msgs::MarkerArray segmentMarkers(const ExecutionPlan& plan, const std::string& frame,
                                               const ros::Time& stamp) {
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  markers.markers.push_back(clear);
  int id = 0;
  for (const PlannedSegment& s : plan.segments) {
    for (int which = 0; which < 3; ++which) {  // goal sphere, label, start sphere
      visualization_msgs::Marker m;
      m.header.frame_id = frame;
      m.header.stamp = stamp;
      m.ns = which == 0 ? "segment_goals" : which == 1 ? "segment_labels" : "segment_starts";
      m.id = id++;
      m.type = which == 1 ? visualization_msgs::Marker::TEXT_VIEW_FACING
                          : visualization_msgs::Marker::SPHERE;
      m.pose = toPoseMsg(which == 2 ? plan.poses[s.begin] : s.goal);
      if (which == 1) m.pose.position.z += 0.05;
      m.scale.x = m.scale.y = m.scale.z = which == 1 ? 0.03 : which == 0 ? 0.025 : 0.015;
      m.color.a = 1.0;
      m.color.r = which == 0 ? 1.0 : 0.9;
      m.color.g = which == 2 ? 0.8 : 0.9;
      m.color.b = which == 1 ? 0.9 : 0.1;
      m.text = s.name;
      markers.markers.push_back(m);
    }
  }
  return markers;
}

}  // namespace lfd_dmp
