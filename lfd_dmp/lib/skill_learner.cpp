#include "lfd_dmp/skill_learner.hpp"

#include <lfd_core/dmp/dmp_generalization.hpp>
#include <lfd_core/dmp/quaternion_log.hpp>
#include <lfd_core/segmentation/smooth_derivatives.hpp>
#include <lfd_core/segmentation/time_alignment.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

lfd::SegmentDemo cut(const DemoRecording& rec, Eigen::Index first, Eigen::Index last) {
  const Eigen::Index n = last - first + 1;
  lfd::SegmentDemo seg;
  seg.times = rec.times.segment(first, n);
  seg.positions = rec.positions.middleRows(first, n);
  if (rec.quaternions.cols() == 4) seg.quaternions = rec.quaternions.middleRows(first, n);
  if (rec.gripper.size() > 0) seg.gripper = rec.gripper.segment(first, n);
  return seg;
}

void checkRecording(const DemoRecording& rec) {
  const Eigen::Index m = rec.times.size();
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("demo " + rec.id + ": " + why);
  };
  if (m < lfd::kMinDmpSamples) fail("has only " + std::to_string(m) + " pose samples");
  if (rec.positions.rows() != m || rec.positions.cols() != 3) fail("positions must be M x 3");
  if (rec.quaternions.size() > 0 && (rec.quaternions.rows() != m || rec.quaternions.cols() != 4)) {
    fail("quaternions must be M x 4");
  }
  if (rec.gripper.size() > 0 && rec.gripper.size() != m) fail("gripper must have M samples");
}

// The recording with its pose low-passed (quaternions on one hemisphere first, renormalized after).
// Non-unit input quaternions are reported as without smoothing.
DemoRecording smoothed(const DemoRecording& rec, double sigma, std::vector<std::string>* warnings) {
  if (sigma <= 0.0) return rec;
  DemoRecording out = rec;
  out.positions = lfd::gaussianSmooth(rec.times, rec.positions, sigma);
  if (rec.quaternions.cols() == 4) {
    const lfd::QuaternionSequence seq = lfd::makeContinuousQuaternions(rec.quaternions);
    if (seq.normalized_input)
      warnings->push_back("demo " + rec.id + ": non-unit quaternions were normalized");
    out.quaternions = lfd::gaussianSmooth(rec.times, lfd::quaternionRows(seq.quaternions), sigma);
    out.quaternions.rowwise().normalize();
  }
  return out;
}

lfd::Pose poseAt(const DemoRecording& rec, Eigen::Index i) {
  lfd::Pose p;
  p.position = rec.positions.row(i).transpose();
  if (rec.quaternions.cols() == 4)
    p.orientation = Eigen::Quaterniond(rec.quaternions(i, 0), rec.quaternions(i, 1),
                                       rec.quaternions(i, 2), rec.quaternions(i, 3))
                        .normalized();
  return p;
}

// Every demo has a scene, or none does (then nothing is learned about goals); all in one frame.
bool checkScenes(const std::vector<DemoRecording>& demos, std::string* frame) {
  size_t with = 0;
  std::string without;
  for (const DemoRecording& d : demos) {
    if (d.scene)
      ++with;
    else
      without += (without.empty() ? "" : ", ") + d.id;
    if (d.frame != demos.front().frame)
      throw std::invalid_argument("demo " + d.id + " has its poses in '" + d.frame + "', demo " +
                                  demos.front().id + " in '" + demos.front().frame + "'");
  }
  if (with > 0 && with < demos.size())
    throw std::invalid_argument(
        "demos without a scene (objects and goal in their metadata): " + without +
        "; the segment goals are learned from every demo's scene");
  *frame = demos.front().frame.empty() ? "base_link" : demos.front().frame;
  return with > 0;
}

// Where each segment of each used demo started and ended, with the demo's scene.
struct DemoEnds {
  lfd::Scene scene;
  lfd::Pose start;
  std::vector<lfd::Pose> bounds;  // segment boundaries: num_segments + 1 poses
};

void learnGoals(const std::vector<DemoEnds>& ends, const lfd::FrameSelectionOptions& options,
                SkillLibrary* lib) {
  for (size_t s = 0; s < lib->segments.size(); ++s) {
    std::vector<lfd::SegmentDemoEnds> demos;
    for (const DemoEnds& e : ends)
      demos.push_back({e.scene, e.start, e.bounds[s], e.bounds[s + 1]});
    lib->segments[s].goal = lfd::learnSegmentGoal(demos, options);
  }
}

// A demo kept for learning: its (smoothed) recording and the sample index of every segment
// boundary (num_segments + 1; segments share boundary samples so consecutive DMPs join).
struct UsedDemo {
  DemoRecording rec;
  std::vector<Eigen::Index> bounds;
};

// Sample indices nearest to each changepoint, with the first and last sample.
std::vector<Eigen::Index> boundaries(const DemoRecording& rec, const std::vector<double>& cps) {
  const Eigen::Index m = rec.times.size();
  std::vector<Eigen::Index> bounds = {0};
  for (double t : cps) {
    if (!std::isfinite(t) || t <= rec.times[0] || t >= rec.times[m - 1]) {
      std::ostringstream msg;
      msg << "demo " << rec.id << ": changepoint at " << t << " s is outside the recording ["
          << rec.times[0] << ", " << rec.times[m - 1] << "]";
      throw std::invalid_argument(msg.str());
    }
    const auto it = std::lower_bound(rec.times.data(), rec.times.data() + m, t);
    Eigen::Index idx = it - rec.times.data();
    if (idx > 0 && t - rec.times[idx - 1] < rec.times[idx] - t) --idx;
    if (idx <= bounds.back())
      throw std::invalid_argument("demo " + rec.id + ": changepoints are not increasing");
    bounds.push_back(idx);
  }
  bounds.push_back(m - 1);
  return bounds;
}

// Segment s of every used demo, re-timed onto one timing when asked (lfd_core time_alignment:
// mixed later, demos timed differently would blur each other's sub-motions), one DMP each.
void learnSegment(const std::vector<UsedDemo>& used, size_t s, const LearnOptions& options,
                  SegmentSkills* seg, std::vector<std::string>* warnings) {
  std::vector<lfd::SegmentDemo> pieces;
  for (const UsedDemo& u : used) pieces.push_back(cut(u.rec, u.bounds[s], u.bounds[s + 1]));
  if (options.time_alignment) {
    const lfd::TimeAlignment aligned = lfd::alignDemoTiming(pieces, *options.time_alignment);
    pieces = aligned.demos;
    seg->time_reference = used[aligned.reference].rec.id;
  }
  for (size_t j = 0; j < used.size(); ++j) {
    const DemoRecording& rec = used[j].rec;
    DemoSkill skill;
    skill.demo_id = rec.id;
    skill.start_time = rec.times[used[j].bounds[s]];
    skill.end_time = rec.times[used[j].bounds[s + 1]];
    try {
      skill.dmp = lfd::SegmentDmp::learn(pieces[j], options.params);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("demo " + rec.id + ", segment " + std::to_string(s) + " [" +
                                  std::to_string(skill.start_time) + ", " +
                                  std::to_string(skill.end_time) + "] s: " + e.what());
    }
    skill.parameters = lfd::goalParameters(skill.dmp);
    for (const auto& w : skill.dmp.warnings)
      warnings->push_back("demo " + rec.id + ", segment " + std::to_string(s) + ": " + w);
    seg->demos.push_back(std::move(skill));
  }
}

// The demos' sensations per segment (lfd_core/dmp/sensory_signature.hpp), cut where their DMPs
// were. Demos without the same sensors are left out of it, with a warning; fewer than two: none.
void learnSignature(const std::vector<UsedDemo>& used, const lfd::SignatureOptions& options,
                    LearnOutcome* out) {
  std::vector<lfd::SegmentedRecording> recordings;
  const DemoRecording* first = nullptr;
  for (const UsedDemo& u : used) {
    const DemoRecording& rec = u.rec;
    if (rec.sensors.rows() < 2) continue;
    if (first && rec.sensors.names != first->sensors.names) {
      out->warnings.push_back("demo " + rec.id +
                              " left out of the sensory signature: its sensors "
                              "differ from demo " +
                              first->id + "'s");
      continue;
    }
    if (!first) first = &rec;
    lfd::SegmentedRecording r;
    r.features = rec.sensors;
    for (std::size_t k = 1; k + 1 < u.bounds.size(); ++k)  // the inner bounds: the changepoints
      r.boundaries.push_back(rec.times[u.bounds[k]] - rec.sensors.timeAt(0));
    recordings.push_back(std::move(r));
  }
  if (recordings.size() < 2) {
    out->warnings.push_back("no sensory signature: " + std::to_string(recordings.size()) +
                            " demo(s) with sensors, 2 needed; reproductions are not monitored");
    return;
  }
  try {
    // The channels of one source are one sensor (its missing contact is judged on all of them).
    const std::vector<std::string>& sources = first->sensor_sources;
    out->library.sensory_signature = lfd::learnSignature(
        recordings, first->sensors.names, options,
        sources.size() == first->sensors.names.size() ? sources : std::vector<std::string>{});
  } catch (const std::invalid_argument& e) {
    out->warnings.push_back(std::string("no sensory signature: ") + e.what());
  }
}

// Majority vote on the number of changepoints (ties: fewer segments).
size_t majorityChangepointCount(const std::vector<std::vector<double>>& changepoint_times) {
  std::map<size_t, size_t> votes;
  for (const auto& cps : changepoint_times) ++votes[cps.size()];
  size_t cp_count = votes.begin()->first;
  for (const auto& [count, n] : votes) {
    if (n > votes[cp_count]) cp_count = count;
  }
  return cp_count;
}

// The library's empty segments, named after the task's when it has as many.
void addSegments(size_t num_segments, const LearnOptions& options, LearnOutcome* outcome) {
  // The task's names fit only the number of segments it has: a 1-segment library of a 3-segment
  // task is not called "approach" (the executor refuses unnamed segments with a clear error).
  const bool named = options.segment_names.size() == num_segments;
  if (!options.segment_names.empty() && !named) {
    outcome->warnings.push_back("the demos give " + std::to_string(num_segments) +
                                " segment(s) (majority of changepoint counts), the task has " +
                                std::to_string(options.segment_names.size()) +
                                ": segments left unnamed; the executor will refuse this library");
  }
  for (size_t s = 0; s < num_segments; ++s) {
    SegmentSkills seg;
    seg.index = static_cast<int>(s);
    seg.name = named ? options.segment_names[s] : "segment_" + std::to_string(s);
    outcome->library.segments.push_back(seg);
  }
}

// The poses of a used demo at its start and at every segment boundary, with its scene.
DemoEnds demoEnds(const UsedDemo& u) {
  DemoEnds e{*u.rec.scene, poseAt(u.rec, 0), {}};
  for (Eigen::Index b : u.bounds) e.bounds.push_back(poseAt(u.rec, b));
  return e;
}

}  // namespace

LearnOutcome learnSkillLibrary(const std::vector<DemoRecording>& demos,
                               const std::vector<std::vector<double>>& changepoint_times,
                               const LearnOptions& options) {
  if (demos.empty()) throw std::invalid_argument("learnSkillLibrary: no demonstrations");
  if (changepoint_times.size() != demos.size()) {
    throw std::invalid_argument("learnSkillLibrary: " + std::to_string(demos.size()) +
                                " demos but " + std::to_string(changepoint_times.size()) +
                                " changepoint lists");
  }
  options.params.validate();
  std::string frame;
  const bool with_scenes = checkScenes(demos, &frame);
  if (!(options.smoothing_sigma >= 0.0) || !std::isfinite(options.smoothing_sigma))
    throw std::invalid_argument("learnSkillLibrary: smoothing_sigma must be a finite value >= 0");
  const size_t cp_count = majorityChangepointCount(changepoint_times);
  const size_t num_segments = cp_count + 1;

  LearnOutcome outcome;
  SkillLibrary& lib = outcome.library;
  lib.task = options.task;
  lib.features = options.features;
  lib.dmp_parameters = options.params;
  lib.smoothing_sigma = options.smoothing_sigma;
  lib.time_alignment = options.time_alignment;
  lib.position_names = {"x", "y", "z"};
  lib.generalization_parameters = "goal_position";
  lib.cartesian_frame = frame;
  addSegments(num_segments, options, &outcome);

  std::vector<DemoEnds> ends;
  std::vector<UsedDemo> used;
  for (size_t d = 0; d < demos.size(); ++d) {
    checkRecording(demos[d]);
    const auto& cps = changepoint_times[d];
    if (cps.size() != cp_count) {
      outcome.warnings.push_back("demo " + demos[d].id + " skipped: " + std::to_string(cps.size()) +
                                 " changepoints, the other demos have " + std::to_string(cp_count));
      continue;
    }
    used.push_back({smoothed(demos[d], options.smoothing_sigma, &outcome.warnings), {}});
    used.back().bounds = boundaries(used.back().rec, cps);
    if (with_scenes) {
      ends.push_back(demoEnds(used.back()));
      lib.demo_scenes[used.back().rec.id] = {ends.back().scene, ends.back().start};
    }
  }
  outcome.demos_used = used.size();
  for (size_t s = 0; s < num_segments && !used.empty(); ++s)
    learnSegment(used, s, options, &lib.segments[s], &outcome.warnings);
  if (outcome.demos_used == 0) {
    throw std::invalid_argument("learnSkillLibrary: no demonstration could be used");
  }
  if (options.signature) learnSignature(used, *options.signature, &outcome);
  if (with_scenes)
    learnGoals(ends, options.frames, &lib);
  else
    outcome.warnings.push_back(
        "no demonstration has a scene (objects and goal in its metadata): no segment goals were "
        "learned, the executor cannot reproduce this library");
  return outcome;
}

}  // namespace lfd_dmp
