// Tasks as data (ROS-free): the workcell's shared facts (config/scene.yaml) and a task file
// (config/tasks/<name>.yaml): the objects the task uses and where they start, its goal, its phases
// as ordered lists of primitives, the per-demonstration variation, and its sim and teleop-like
// configurations. The physical success criterion of a task file is read by the Python judge
// (lfd_tools.judge) only: the demonstrator never judges. Loading checks everything a demonstration
// needs, so a bad file fails before anything moves, with an error naming the file and the key.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "lfd_core/kinematics/pose.hpp"

namespace lfd_sim_bridge {
namespace task {

using Pose = lfd::Pose;

// A frame of an object (e.g. a drawer's handle), in the object's frame, moving with `joint`
// (along the joint's axis, by the joint's value) when it names one.
struct ObjectFrame {
  Pose pose;
  std::string joint;
  std::string body;  // the simulator's body at this frame, reported on /objects/<body>/pose
};

struct SceneJoint {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // in the object's frame (slide)
  double lower = 0.0, upper = 0.0;                  // m
};

struct SceneObject {
  std::string name;
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();  // m, its collision box
  Pose park;                                            // world: where it waits when unused
  bool fixed = false;                                   // placed, never moved by contact
  std::map<std::string, ObjectFrame> frames;            // named frames ("handle")
  std::map<std::string, SceneJoint> joints;             // articulated joints
};

// Bounds of every task file, written once in the scene file's task_limits (config/scene.yaml),
// where both loaders read them: this one and lfd_tools.tasks.
struct TaskLimits {
  double max_step_seconds = 0.0;  // any time of a task file: a duration, a hold, a settle
  int max_nesting_depth = 0;      // mappings and lists within one another (the file is 1)
};

struct Scene {
  std::string path;
  TaskLimits task_limits;
  double table_top = 0.0;                                   // world z of the table surface
  Eigen::Vector3d base_in_world = Eigen::Vector3d::Zero();  // base_link (no rotation)
  Eigen::Quaterniond tool_orientation = Eigen::Quaterniond::Identity();  // TCP at yaw 0
  std::vector<SceneObject> objects;                                      // file order
  const SceneObject* find(const std::string& name) const;                // nullptr when unknown
};

// Throws std::runtime_error naming the file and the key.
Scene loadScene(const std::string& path);

// A pose relative to a named frame: an object (its start pose as the demonstrator aims at it), an
// object's frame ("drawer.handle"), goal, start (the TCP when the demo starts), base (base_link),
// tcp (the TCP where the step starts) or a frame the task defines. Every frame is horizontal: a
// position and a yaw (z up). The TCP takes the scene's tool orientation turned by the frame's yaw
// (plus `yaw`), except relative to tcp and start, whose orientation it keeps.
struct PoseSpec {
  std::string frame;
  std::string axes;  // frame whose yaw orients `position` (default: `frame`)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // m
  double yaw = 0.0;                                    // rad added to the frame's yaw
  // The tool looks the same turned by 2 pi / symmetry (2: a parallel gripper across a bar): the
  // TCP yaw is wrapped into (-pi/symmetry, pi/symmetry], where the wrist is comfortable.
  int symmetry = 1;
};

enum class StepKind { kMove, kCarry, kPush, kGripper, kHold };
enum class Contact { kNone, kAny, kBoth };  // any finger pad / both pads touch

// One primitive. Durations are nominal seconds at speed 1.
struct Step {
  StepKind kind = StepKind::kHold;
  std::string where;  // "phases[1].steps[0]", for messages
  std::string label;  // names the motion in logs and plans
  double duration = 0.0;
  PoseSpec target;    // move, carry, push
  std::string held;   // carry, push: the object (or object frame) the hand moves
  bool open = false;  // gripper: open (release) or close
  // move: stop once the pads touch (a guarded move); gripper close: close until both pads touch
  // (sim mode; the teleop operator closes for a fixed time). Ends its phase.
  Contact until_contact = Contact::kNone;
  double settle = 0.0;  // s held after the contact
};

struct PhaseSpec {
  std::string name;
  // A transition window, not a skill: the expected changepoint between the skills before and
  // after it lies in it (grasp's "grasp" phase, the gripper closing).
  bool window = false;
  std::vector<Step> steps;
};

// A frame the task defines from others.
struct FrameSpec {
  enum class Kind { kRelative, kHeading, kTouch };
  Kind kind = Kind::kRelative;
  std::string where;
  PoseSpec relative;          // kRelative: `position`/`yaw` relative to `frame` (axes: `axes`)
  std::string from, to;       // kHeading: at `from`, x pointing (horizontally) toward `to`
  std::string object, along;  // kTouch: where the closed fist first touches `object` moving
                              // along the x axis of `along` (its yaw)
};

// Uniform +-range drawn per demonstration, in the object's axes: where the hand takes it.
struct Jitter {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // m
  double yaw = 0.0;                                    // rad
};

struct Configuration {
  int id = 0;
  std::map<std::string, Pose> objects;   // world: start pose of each object the task uses
  Pose goal;                             // world
  std::map<std::string, double> joints;  // articulated joints' start values (default 0)
};

struct TaskDefinition {
  std::string name, path;
  std::vector<std::string> objects;                       // the scene objects the task uses
  std::vector<std::pair<std::string, FrameSpec>> frames;  // in definition order
  std::map<std::string, Jitter> variation;
  std::map<std::string, Jitter> teleop_placement;  // the teleop operator's misjudgement, per object
  bool gripper_closed_at_start = false;            // the robot starts with the gripper closed
  std::vector<PhaseSpec> phases;
  std::map<std::string, std::vector<Configuration>> configurations;  // "sim", "teleop"
  std::map<std::string, std::vector<Configuration>> unseen;          // reproduction goals

  // Articulated joints of the objects the task uses.
  std::vector<std::string> joints(const Scene& scene) const;
};

// Throws std::runtime_error naming the file and the key: a missing or malformed entry, an unknown
// object, frame or primitive, a guarded move that is not the last step of its phase, a carry
// before any gripper close, a number that is not finite, a time over the scene's
// max_step_seconds; and naming the file: bytes that are not printable UTF-8 text, nesting deeper
// than max_nesting_depth, a key given twice, a tag (task files use none).
TaskDefinition loadTask(const std::string& path, const Scene& scene);

// <dir>/<name>.yaml
std::string taskFilePath(const std::string& tasks_dir, const std::string& name);

// Built-in frame names (besides the task's objects and their frames).
bool isBuiltinFrame(const std::string& name);

}  // namespace task
}  // namespace lfd_sim_bridge
