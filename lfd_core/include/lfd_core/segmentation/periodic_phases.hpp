// The periodic phases of a task's demos (reciprocating_motion.hpp finds them in one demo), and on
// which state features they are looked for.
//
// First on the features II-B selected, the ones the demos move consistently: a wrist that turns a
// little at random in each demo adds its own drift to every stroke and hides the reversals. At
// least two of them: along a single feature every reversal goes straight back, and the test of
// direction says nothing (PR2's one selected joint: its wiggles while a leg is screwed in were
// taken for a periodic phase, 3/6 -> 2/6 at 1 s).
//
// The strokes may run along a feature II-B left out: a grater reached along y and z and worked
// along x, whose strokes differ in count and length from demo to demo, so that x correlates
// poorly across the demos. Where the selected features show no periodic phase and the task has
// no contact sensor (then the motion is the only evidence), each pair of the features that move
// above their noise is tried, and the pair whose periodic phases cover the most of the demo
// wins. With a contact sensor, its events mark a wipe's strokes, and a phase found on such a pair
// only competes with them (the stroke and drifting-F/T classes lost 5% when it was tried).
//
// No periodic phase holds a pause: strokes separated by still pauses are an operator's separate
// motions (the pause class went from 1.00 to 0.38 when the pairs ran without this rule).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "lfd_core/segmentation/boundary_evidence.hpp"
#include "lfd_core/segmentation/reciprocating_motion.hpp"
#include "lfd_core/segmentation/time_series.hpp"

namespace lfd {

struct PeriodicPhaseConfig {
  /// The Gaussian sigma of the speed (s; PauseConfig::smoothing).
  double smoothing = 0.1;
  /// A feature the pairs may use moves at least this many noise sigmas in some demo
  /// (state_features.hpp: featuresAboveNoise).
  double min_range_sigmas = 20.0;
  ReciprocationConfig reciprocation;
};

/// Each demo's periodic phases. `moving`: the task's moving state features; `selected`: those
/// II-B selected (empty: all of `moving`); `pauses`: each demo's pauses (findPauses);
/// `contact_sensed`: whether the task has a contact sensor. Throws std::invalid_argument when
/// `pauses` and `demos` differ in count.
std::vector<std::vector<ReciprocatingRun>> periodicPhases(
    const std::vector<FeatureMatrix>& demos, const std::vector<std::string>& moving,
    const std::vector<std::string>& selected, const std::vector<std::vector<Pause>>& pauses,
    bool contact_sensed, const PeriodicPhaseConfig& config, int threads = 1);

}  // namespace lfd
