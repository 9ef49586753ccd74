// Skill library: one readable, versioned JSON file per task holding, for every segment, the DMPs
// learned on each demonstration with the task parameters (goal features) used to generalize.
//
// {
//   "format": "lfd_skill_library", "version": 2, "task": "grasp",
//   "cartesian_frame": "base_link",                 // frame of every pose below
//   "demo_scenes": [{"demo_id": "grasp_03.bag",      // the scene of each demo (learned goals)
//                    "start": POSE, "objects": {"stick": POSE}, "goal": POSE}],
//   "features": ["gripper_opening", "ee_speed", "ee_x"],          // features used to segment
//   "generalization_parameters": "goal_position",
//   "position_names": ["x", "y", "z"],
//   "dmp_parameters": {"num_basis": 50, "alpha_x": 6.9, ...},
//   "smoothing_sigma": 0.05,                         // s, the demos' low-pass before learning
//   "time_alignment": {"sample_seconds": 0.05, "warp_sigma": 0.1, "yaw_invariant": true},
//                                                    // each segment's demos re-timed onto one
//                                                    // timing (absent: learned as recorded)
//   "segments": [
//     {"index": 0, "name": "approach",
//      "time_reference": "grasp_05.bag",              // the demo the timing was aligned to
//      "goal": {"position": {"frame": "object:stick", "offset": [x, y, z], "spread_m": 0.008},
//               "orientation": {"frame": "object:stick", "offset": [w, x, y, z],
//                               "spread_rad": 0.04},
//               "heading": {"frame": "", "spread_rad": 1.2},   // motion follows its x ("": none)
//               "candidates": [{"frame": "base", "position_spread_m": 0.1,
//                               "orientation_spread_rad": 0.2}, ...]},  // null = undefined
//      "demos": [{"demo_id": "grasp_03.bag", "start_time": 0.0, "end_time": 4.1,
//                 "parameters": [0.6, -0.1, 0.8],
//                 "dmp": {"tau": 4.1,
//                         "position": {"start": [...], "goal": [...], "start_velocity": [...],
//                                      "weights": [[N values of x], [N of y], [N of z]]},
//                         "orientation": {"start": [w,x,y,z], "goal": [w,x,y,z],
//                                         "start_angular_velocity": [...], "weights": [[N]x3]},
//                         "gripper": {"start": 0.08, "goal": 0.0, "start_velocity": 0.0,
//                                     "weights": [N values]}}}]}]
// }
// POSE = {"position": [x, y, z], "orientation": [w, x, y, z]}. "goal" and "demo_scenes" are
// optional (a library learned without scenes, e.g. by dmp_tool, has none; the executor refuses it).
// Loading validates everything (format, version, shapes, finite numbers) and reports the exact
// JSON location of the first problem. Version 1 (goals written by hand in the executor's config)
// is refused with a request to relearn.
#pragma once

#include <lfd_core/dmp/segment_dmp.hpp>
#include <lfd_core/dmp/sensory_signature.hpp>
#include <lfd_core/dmp/task_frames.hpp>
#include <lfd_core/segmentation/time_alignment.hpp>

#include "lfd_dmp/library_limits.hpp"

#include <lfd_core/io/safe_paths.hpp>

#include <nlohmann/json.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace lfd_dmp {

constexpr int kSkillLibraryVersion = 2;
constexpr const char* kSkillLibraryFormat = "lfd_skill_library";

/// The DMPs of one segment learned on one demonstration.
struct DemoSkill {
  std::string demo_id;         ///< e.g. the bag file name
  double start_time = 0.0;     ///< segment start within the demo [s]
  double end_time = 0.0;       ///< segment end within the demo [s]
  Eigen::VectorXd parameters;  ///< task parameters for generalization (default: goal position)
  lfd::SegmentDmp dmp;
};

struct SegmentSkills {
  int index = 0;
  std::string name;  ///< e.g. "approach", or "segment_0"
  std::vector<DemoSkill> demos;
  std::optional<lfd::SegmentGoalModel> goal;  ///< where the segment ends, learned from the scenes
  std::string time_reference;  ///< the demo whose DTW the others were aligned to ("": none)
};

/// Where a demonstration happened (Cartesian frame): its scene and the TCP pose when it started.
struct DemoScene {
  lfd::Scene scene;
  lfd::Pose start;
};

struct SkillLibrary {
  int version = kSkillLibraryVersion;
  std::string task;
  std::vector<std::string> features;  ///< selected segmentation features
  std::string generalization_parameters = "goal_position";
  std::vector<std::string> position_names = {"x", "y", "z"};  ///< names of the position dims
  lfd::DmpParameters dmp_parameters;
  /// s; the Gaussian low-pass applied to the demos before learning (LearnOptions; 0 = none).
  /// Optional in the file (absent = 0, as written before it was recorded).
  double smoothing_sigma = 0.0;
  /// How each segment's demos were re-timed onto one timing before learning (none: as recorded).
  std::optional<lfd::TimeAlignmentOptions> time_alignment;
  std::string cartesian_frame = "base_link";     ///< frame of the poses (DMPs, scenes, goals)
  std::map<std::string, DemoScene> demo_scenes;  ///< by demo_id
  std::vector<SegmentSkills> segments;
  /// What each segment's sensors showed in the demos (none: learned without sensors, or by an
  /// older learner); the executor monitors a reproduction against it.
  std::optional<lfd::SensorySignature> sensory_signature;
};

nlohmann::json toJson(const lfd::DmpParameters& params);
nlohmann::json toJson(const lfd::SegmentDmp& dmp);
nlohmann::json toJson(const SkillLibrary& library);

/// `where` prefixes error messages (a JSON path such as "segments[0].demos[1].dmp").
lfd::DmpParameters dmpParametersFromJson(const nlohmann::json& j, const std::string& where);
lfd::SegmentDmp segmentDmpFromJson(const nlohmann::json& j, const lfd::DmpParameters& params,
                                   const std::string& where);
/// Throws std::runtime_error naming the JSON location on any problem.
SkillLibrary skillLibraryFromJson(const nlohmann::json& j);

/// What a skill library file is, for outputs: a JSON object whose "format" is kSkillLibraryFormat
/// (every library lfd ever wrote has it). `overwrite` replaces only such a file.
lfd::OutputKind skillLibraryOutput();

/// Writes pretty-printed JSON atomically (lfd::writeFileAtomically). An existing file is kept
/// (std::invalid_argument) unless `overwrite`, and even then unless it is a skill library lfd
/// wrote. The library must load again within `limits` (its strings, lists and counts: a request's
/// 200 KB task name would otherwise make a library no node can load): else std::runtime_error
/// "<JSON location>: ..." and nothing is written. Throws std::runtime_error on I/O errors.
void saveSkillLibrary(const SkillLibrary& library, const std::string& path, bool overwrite,
                      const LibraryLimits& limits = {});
/// Only regular files are read (a FIFO is refused, never opened), within `limits` (file size,
/// sizes, durations: library_limits.hpp). Throws std::runtime_error with the file name and the
/// JSON location of the problem.
SkillLibrary loadSkillLibrary(const std::string& path, const LibraryLimits& limits = {});

}  // namespace lfd_dmp
