#include "lfd_dmp/object_following.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {

void checkFollowOptions(const FollowOptions& o) {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("follow_objects/") + name + " must be > 0");
  };
  positive(o.check_period, "check_period");
  positive(o.lead, "lead");
  if (!(o.until_fraction >= 0.0 && o.until_fraction <= 1.0))
    throw std::invalid_argument("follow_objects/until_fraction must be in [0, 1]");
  if (!(o.min_shift >= 0.0) || !std::isfinite(o.min_shift) || !(o.min_turn >= 0.0) ||
      !std::isfinite(o.min_turn))
    throw std::invalid_argument("follow_objects/min_shift and min_turn must be >= 0");
}

std::map<std::string, double> followWindows(const SkillLibrary& library, const ExecutionPlan& plan,
                                            const FollowOptions& options) {
  std::map<std::string, double> windows;
  for (std::size_t s = 0; s < library.segments.size() && s < plan.segments.size(); ++s) {
    // An empty segment was done before the plan (a retry after a recovery): not followed there.
    if (!library.segments[s].goal || plan.segments[s].end == plan.segments[s].begin) continue;
    const lfd::SegmentGoalModel& g = *library.segments[s].goal;
    std::vector<const lfd::SceneFrame*> frames{&g.position_frame, &g.orientation_frame};
    if (g.motion_frame) frames.push_back(&*g.motion_frame);
    // A later segment starts where the one before ended (its first sample is one step in).
    const std::size_t first = plan.segments[s].begin;
    const double begin = first > 0 ? plan.times[first - 1] : plan.times[first];
    const double end = begin + options.until_fraction * plan.segments[s].duration;
    for (const lfd::SceneFrame* f : frames)
      if (!f->object.empty()) windows.emplace(f->object, end);  // the first segment's stays
  }
  return windows;
}

std::vector<ObjectMove> movedObjects(const lfd::Scene& planned,
                                     const std::map<std::string, lfd::Pose>& now,
                                     const std::map<std::string, double>& windows, double elapsed,
                                     const FollowOptions& options) {
  std::vector<ObjectMove> moves;
  for (const auto& [name, until] : windows) {
    if (elapsed >= until) continue;
    const auto was = planned.objects.find(name);
    const auto is = now.find(name);
    if (was == planned.objects.end() || is == now.end()) continue;
    ObjectMove m{name, (is->second.position - was->second.position).norm(),
                 is->second.orientation.angularDistance(was->second.orientation)};
    if (m.shift >= options.min_shift || m.turn >= options.min_turn) moves.push_back(m);
  }
  return moves;
}

std::string describeMoves(const std::vector<ObjectMove>& moves) {
  std::ostringstream out;
  out.precision(2);
  out << std::fixed;
  for (std::size_t i = 0; i < moves.size(); ++i)
    out << (i ? ", " : "") << "object '" << moves[i].object << "' moved " << moves[i].shift * 100.0
        << " cm and turned " << moves[i].turn * 180.0 / M_PI << " deg";
  return out.str();
}

}  // namespace lfd_dmp
