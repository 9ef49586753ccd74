// Learner (paper II-D): cut every demonstration at its validated changepoints and learn one
// SegmentDmp (end-effector position + orientation + gripper on one phase) per segment per demo.
// ROS-free apart from the bag reader (demo_bag.hpp), so it is unit-tested without a master.
#pragma once

#include "lfd_core/dmp/sensory_signature.hpp"
#include "lfd_core/segmentation/time_series.hpp"
#include "lfd_dmp/skill_library.hpp"

#include <optional>
#include <string>
#include <vector>

namespace lfd_dmp {

/// One recorded demonstration, resampled on the end-effector pose time stamps.
struct DemoRecording {
  std::string id;                     ///< e.g. the bag path
  Eigen::VectorXd times;              ///< M, strictly increasing (bag time, s)
  Eigen::MatrixXd positions;          ///< M x 3, end effector in base_link
  Eigen::MatrixXd quaternions;        ///< M x 4 (w, x, y, z)
  Eigen::VectorXd gripper;            ///< M gripper opening (empty if not recorded)
  std::string frame;                  ///< frame of the poses ("" = not recorded)
  std::optional<lfd::Scene> scene;    ///< the demo's scene in that frame (none recorded: empty)
  std::vector<std::string> warnings;  ///< what reading it found (stamps out of order, gaps)
  /// The sensors the demo recorded (feature names, on the same clock as `times`), for the
  /// sensory signature; empty: none read.
  lfd::FeatureMatrix sensors;
  std::vector<std::string> sensor_sources;  ///< per sensor column, its topic (optional)
};

struct LearnOptions {
  std::string task;
  std::vector<std::string> features;  ///< selected segmentation features (stored)
  /// optional: the task's segment names, used only when the majority vote gives that many segments
  /// (otherwise "segment_<i>" and a warning); default "segment_<i>"
  std::vector<std::string> segment_names;
  lfd::DmpParameters params;
  /// s; Gaussian low-pass of every recorded pose before it is cut and learned (lfd::gaussianSmooth;
  /// 0 = off). Teleoperated demos carry tremor that the DMPs would otherwise replay.
  double smoothing_sigma = 0.0;
  /// Re-time each segment's demos onto one common timing before learning them (lfd_core
  /// time_alignment; none = learn them as recorded). The executor mixes the demos' DMPs phase by
  /// phase: demos whose sub-motions come at different phases would blur each other.
  std::optional<lfd::TimeAlignmentOptions> time_alignment;
  /// How each segment's goal frame is chosen from the demos' scenes (lfd_core task_frames).
  lfd::FrameSelectionOptions frames;
  /// Learn each segment's sensory signature from the demos' `sensors` (none: not learned).
  std::optional<lfd::SignatureOptions> signature;
};

struct LearnOutcome {
  SkillLibrary library;
  std::vector<std::string> warnings;
  size_t demos_used = 0;
};

/// changepoint_times[i]: sorted changepoint times of demos[i] (same clock as its times).
/// The number of segments is the most common changepoint count + 1; demos with another count are
/// skipped with a warning (they were not segmented consistently). When the demos carry scenes, each
/// segment's goal frame is learned from them (lfd::learnSegmentGoal) and the scenes are stored;
/// without any scene the library has no goals (a warning: the executor cannot reproduce it).
/// Throws std::invalid_argument on unusable input (no demos, changepoints outside a demo, a segment
/// too short to learn, NaN, scenes for only some demos, poses in different frames).
LearnOutcome learnSkillLibrary(const std::vector<DemoRecording>& demos,
                               const std::vector<std::vector<double>>& changepoint_times,
                               const LearnOptions& options);

}  // namespace lfd_dmp
