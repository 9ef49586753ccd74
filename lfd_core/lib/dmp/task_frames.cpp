#include "lfd_core/dmp/task_frames.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lfd {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

const std::map<SceneFrame::Kind, std::string>& kindNames() {
  static const std::map<SceneFrame::Kind, std::string> kNames = {
      {SceneFrame::Kind::kBase, "base"},       {SceneFrame::Kind::kStart, "start"},
      {SceneFrame::Kind::kObject, "object"},   {SceneFrame::Kind::kGoal, "goal"},
      {SceneFrame::Kind::kHeading, "heading"}, {SceneFrame::Kind::kGoalHeading, "goal_heading"}};
  return kNames;
}

bool namesObject(SceneFrame::Kind k) {
  return k == SceneFrame::Kind::kObject || k == SceneFrame::Kind::kHeading ||
         k == SceneFrame::Kind::kGoalHeading;
}

const Pose& objectPose(const Scene& scene, const std::string& name) {
  const auto it = scene.objects.find(name);
  if (it == scene.objects.end()) {
    std::string known;
    for (const auto& [n, p] : scene.objects) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("the scene has no object '" + name +
                                "' (it has: " + (known.empty() ? "none" : known) + ")");
  }
  return it->second;
}

Eigen::Quaterniond yawQuaternion(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

void requireFinite(const Pose& p, const std::string& what) {
  if (!p.position.allFinite() || !p.orientation.coeffs().allFinite())
    throw std::invalid_argument(what + " is not finite");
}

// The objects every demo's scene names: the only ones a frame can be learned on.
std::vector<std::string> commonObjects(const std::vector<SegmentDemoEnds>& demos) {
  std::vector<std::string> out;
  for (const auto& [name, pose] : demos.front().scene.objects) {
    bool everywhere = true;
    for (const SegmentDemoEnds& d : demos) everywhere = everywhere && d.scene.objects.count(name);
    if (everywhere) out.push_back(name);
  }
  return out;
}

double wrapAngle(double a) {
  return std::atan2(std::sin(a), std::cos(a));
}

// Offsets of the segment ends in one frame (empty when the frame is undefined in some demo).
std::vector<Pose> offsetsIn(const SceneFrame& frame, const std::vector<SegmentDemoEnds>& demos,
                            const FrameOptions& options) {
  std::vector<Pose> offsets;
  for (const SegmentDemoEnds& d : demos) {
    Pose f;
    try {
      f = framePose(frame, d.scene, d.task_start, options);
    } catch (const std::invalid_argument&) {
      return {};
    }
    offsets.push_back(toPose(toIsometry(f).inverse() * toIsometry(d.segment_end)));
  }
  return offsets;
}

struct OffsetStats {
  Eigen::Vector3d mean_position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond mean_orientation = Eigen::Quaterniond::Identity();
  double position_rms = kInf, orientation_rms = kInf;
  double distance = kInf;  // mean distance of the segment end from the frame's origin
};

OffsetStats statistics(const std::vector<Pose>& offsets) {
  OffsetStats s;
  if (offsets.empty()) return s;
  std::vector<Eigen::Quaterniond> qs;
  s.distance = 0.0;
  for (const Pose& o : offsets) {
    s.mean_position += o.position / static_cast<double>(offsets.size());
    s.distance += o.position.norm() / static_cast<double>(offsets.size());
    qs.push_back(o.orientation);
  }
  s.mean_orientation = meanQuaternion(qs);
  double p2 = 0.0, a2 = 0.0;
  for (const Pose& o : offsets) {
    p2 += (o.position - s.mean_position).squaredNorm();
    const double a = o.orientation.angularDistance(s.mean_orientation);
    a2 += a * a;
  }
  s.position_rms = std::sqrt(p2 / offsets.size());
  s.orientation_rms = std::sqrt(a2 / offsets.size());
  return s;
}

// The smaller spread wins. Frames that explain the demos equally (e.g. the goal's and the object's
// orientation when every demo carried the object at its own yaw; the base and the start when
// every demo started at home) are told apart by where the end is: the frame whose origin it lies
// nearest to (by over a micrometre: else the first in candidate order stays). Equal spreads: within
// kTieSpread (10 um or urad, far below any sensor's resolution) plus 0.1%.
constexpr double kTieSpread = 1e-5;

bool better(double spread, double distance, double best_spread, double best_distance) {
  if (!std::isfinite(spread)) return false;
  if (!std::isfinite(best_spread)) return true;
  const double tie = kTieSpread + 1e-3 * best_spread;
  if (spread < best_spread - tie) return true;
  return spread <= best_spread + tie && distance < best_distance - 1e-6;
}

// How much larger than the smallest a spread of `demos` demos may be by sampling noise alone: the
// log of an RMS from d = demos - 1 degrees of freedom has a standard deviation of ~1 / sqrt(2 d)
// (and the difference of two such logs ~1 / sqrt(d)), so exp(z / sqrt(d)). 1 for one demo or z 0.
double noiseRatio(double z, std::size_t demos) {
  return demos > 1 && z > 0 ? std::exp(z / std::sqrt(static_cast<double>(demos - 1))) : 1.0;
}

// The candidate with the smallest position spread, or, among those within `ratio` of it (and the
// exact ties of better()), the one whose origin the segment end lies nearest to.
const std::pair<SceneFrame, OffsetStats>& nearestOfTheBest(
    const std::vector<std::pair<SceneFrame, OffsetStats>>& candidates, double ratio) {
  const std::pair<SceneFrame, OffsetStats>* best = &candidates.front();
  for (const auto& c : candidates)
    if (better(c.second.position_rms, c.second.distance, best->second.position_rms,
               best->second.distance))
      best = &c;
  const double within = best->second.position_rms * ratio;
  const std::pair<SceneFrame, OffsetStats>* chosen = best;
  for (const auto& c : candidates)
    if (c.second.position_rms <= within && c.second.distance < chosen->second.distance - 1e-6)
      chosen = &c;
  return *chosen;
}

// RMS angle between each demo's horizontal motion and the x axis of `frame` (infinite when either
// is undefined in some demo).
double motionSpread(const SceneFrame& frame, const std::vector<SegmentDemoEnds>& demos,
                    const FrameSelectionOptions& options) {
  double sum = 0.0;
  for (const SegmentDemoEnds& d : demos) {
    try {
      const double motion =
          headingYaw(d.segment_start.position, d.segment_end.position, options.min_motion_length);
      const double a =
          wrapAngle(motion - poseYaw(framePose(frame, d.scene, d.task_start, options.frames)));
      sum += a * a;
    } catch (const std::invalid_argument&) {
      return kInf;
    }
  }
  return std::sqrt(sum / demos.size());
}

}  // namespace

std::string SceneFrame::name() const {
  const std::string& k = kindNames().at(kind);
  return namesObject(kind) ? k + ":" + object : k;
}

SceneFrame SceneFrame::parse(const std::string& name) {
  const auto colon = name.find(':');
  const std::string kind = name.substr(0, colon);
  for (const auto& [k, text] : kindNames()) {
    if (text != kind) continue;
    SceneFrame f;
    f.kind = k;
    if (namesObject(k)) {
      if (colon == std::string::npos || colon + 1 == name.size())
        throw std::invalid_argument("frame '" + name + "' needs an object name: " + kind +
                                    ":<name>");
      f.object = name.substr(colon + 1);
    } else if (colon != std::string::npos) {
      throw std::invalid_argument("frame '" + name + "': " + kind + " takes no object name");
    }
    return f;
  }
  throw std::invalid_argument("unknown frame '" + name +
                              "' (base | start | goal | object:<o> | heading:<o> | "
                              "goal_heading:<o>)");
}

std::vector<SceneFrame> candidateFrames(const Scene& scene) {
  using K = SceneFrame::Kind;
  std::vector<SceneFrame> out = {{K::kBase, ""}, {K::kStart, ""}, {K::kGoal, ""}};
  for (const auto& [name, pose] : scene.objects)
    for (K k : {K::kObject, K::kHeading, K::kGoalHeading}) out.push_back({k, name});
  return out;
}

double headingYaw(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double min_length) {
  const Eigen::Vector2d d = (to - from).head<2>();
  if (!d.allFinite() || !(d.norm() >= min_length)) {
    std::ostringstream m;
    m << "its start and end are " << d.norm()
      << " m apart horizontally (a heading needs >= " << min_length << " m)";
    throw std::invalid_argument(m.str());
  }
  return std::atan2(d.y(), d.x());
}

double sceneHeading(const Scene& scene, const std::string& object, const FrameOptions& options) {
  try {
    return headingYaw(objectPose(scene, object).position, scene.goal.position,
                      options.min_heading_length);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("no heading of '" + object + "' toward the goal: " + e.what());
  }
}

double poseYaw(const Pose& pose) {
  const Eigen::Vector3d x = pose.orientation * Eigen::Vector3d::UnitX();
  if (!x.allFinite() || x.head<2>().norm() < std::abs(x.z()))
    throw std::invalid_argument("the frame's x axis is closer to vertical than horizontal: no yaw");
  return std::atan2(x.y(), x.x());
}

Pose framePose(const SceneFrame& frame, const Scene& scene, const Pose& start,
               const FrameOptions& options) {
  using K = SceneFrame::Kind;
  switch (frame.kind) {
    case K::kBase:
      return Pose();
    case K::kStart:
      return start;
    case K::kObject:
      return objectPose(scene, frame.object);
    case K::kGoal:
      return scene.goal;
    case K::kHeading:
    case K::kGoalHeading: {
      Pose p;
      p.orientation = yawQuaternion(sceneHeading(scene, frame.object, options));
      p.position = frame.kind == K::kHeading ? objectPose(scene, frame.object).position
                                             : scene.goal.position;
      return p;
    }
  }
  throw std::invalid_argument("framePose: unknown frame kind");
}

Eigen::Quaterniond meanQuaternion(const std::vector<Eigen::Quaterniond>& qs) {
  if (qs.empty()) throw std::invalid_argument("meanQuaternion: no quaternions");
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  for (const Eigen::Quaterniond& q : qs) {
    const Eigen::Vector4d c = q.normalized().coeffs();
    m += c * c.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(m);
  Eigen::Vector4d c = solver.eigenvectors().col(3);  // largest eigenvalue last
  if (c.dot(qs.front().coeffs()) < 0.0) c = -c;      // the inputs' hemisphere, for readability
  return Eigen::Quaterniond(c[3], c[0], c[1], c[2]).normalized();
}

SegmentGoalModel learnSegmentGoal(const std::vector<SegmentDemoEnds>& demos,
                                  const FrameSelectionOptions& options) {
  if (demos.empty()) throw std::invalid_argument("learnSegmentGoal: no demonstrations");
  for (const SegmentDemoEnds& d : demos) {
    requireFinite(d.task_start, "a demo's start pose");
    requireFinite(d.segment_start, "a demo's segment start");
    requireFinite(d.segment_end, "a demo's segment end");
    requireFinite(d.scene.goal, "a demo's goal");
    for (const auto& [name, pose] : d.scene.objects) requireFinite(pose, "object " + name);
  }
  Scene common;
  for (const std::string& name : commonObjects(demos)) common.objects[name] = Pose();
  SegmentGoalModel model;
  OffsetStats best_orientation;
  std::vector<std::pair<SceneFrame, OffsetStats>> positions;
  for (const SceneFrame& frame : candidateFrames(common)) {
    const OffsetStats s = statistics(offsetsIn(frame, demos, options.frames));
    model.candidates.push_back({frame, s.position_rms, s.orientation_rms});
    positions.emplace_back(frame, s);
    if (better(s.orientation_rms, s.distance, best_orientation.orientation_rms,
               best_orientation.distance)) {
      best_orientation = s;
      model.orientation_frame = frame;
      model.orientation_offset = s.mean_orientation;
    }
  }
  // `base` is always defined, so both are chosen.
  const auto& [position_frame, best_position] =
      nearestOfTheBest(positions, noiseRatio(options.tie_z, demos.size()));
  model.position_frame = position_frame;
  model.position_offset = best_position.mean_position;
  model.position_spread = best_position.position_rms;
  model.orientation_spread = best_orientation.orientation_rms;
  // The frame whose x axis the motion follows best (the base frame's would change nothing).
  double best_motion = kInf;
  for (const SceneFrame& frame : candidateFrames(common)) {
    if (frame.kind == SceneFrame::Kind::kBase) continue;
    const double spread = motionSpread(frame, demos, options);
    if (spread < best_motion) {
      best_motion = spread;
      model.motion_frame = frame;
    }
  }
  model.motion_spread = best_motion;
  if (!(best_motion <= options.heading_tolerance)) model.motion_frame.reset();
  return model;
}

Pose segmentGoal(const SegmentGoalModel& model, const Scene& scene, const Pose& start,
                 const FrameOptions& options) {
  const Pose p = framePose(model.position_frame, scene, start, options);
  const Pose o = framePose(model.orientation_frame, scene, start, options);
  Pose goal;
  goal.position = p.position + p.orientation * model.position_offset;
  goal.orientation = (o.orientation * model.orientation_offset).normalized();
  return goal;
}

}  // namespace lfd
