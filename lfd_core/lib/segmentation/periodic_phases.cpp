// The periodic phases of a task's demos (see periodic_phases.hpp).
#include "lfd_core/segmentation/periodic_phases.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "lfd_core/segmentation/state_features.hpp"
#include "lfd_core/util/parallel_for.hpp"

namespace lfd {
namespace {

using Runs = std::vector<ReciprocatingRun>;

bool holdsPause(const ReciprocatingRun& run, const std::vector<Pause>& pauses) {
  return std::any_of(pauses.begin(), pauses.end(),
                     [&](const Pause& p) { return p.end > run.begin && p.begin < run.end; });
}

// The runs of `states` (speed: their speed profile) that hold no pause.
Runs pauseFreeRuns(const Eigen::MatrixXd& states, const Eigen::VectorXd& speed,
                   const std::vector<Pause>& pauses, const PeriodicPhaseConfig& config) {
  Runs runs = reciprocatingRuns(states, speed, config.reciprocation);
  runs.erase(std::remove_if(runs.begin(), runs.end(),
                            [&](const ReciprocatingRun& run) { return holdsPause(run, pauses); }),
             runs.end());
  return runs;
}

std::size_t coverage(const Runs& runs) {
  std::size_t samples = 0;
  for (const ReciprocatingRun& run : runs) samples += run.end - run.begin;
  return samples;
}

// The runs of the pair of `states`' columns whose runs cover the most samples. Each feature is
// smoothed once: a pair's speed is the norm of its two velocity columns.
Runs bestPairRuns(const Eigen::MatrixXd& states, const std::vector<double>& clock,
                  const std::vector<Pause>& pauses, const PeriodicPhaseConfig& config) {
  Runs best;
  if (states.rows() < 5) return best;
  const Eigen::MatrixXd velocity = stateVelocities(states, clock, config.smoothing);
  Eigen::MatrixXd pair(states.rows(), 2);
  for (Eigen::Index i = 0; i < states.cols(); ++i) {
    for (Eigen::Index j = i + 1; j < states.cols(); ++j) {
      pair << states.col(i), states.col(j);
      const Eigen::VectorXd speed =
          (velocity.col(i).array().square() + velocity.col(j).array().square()).sqrt();
      Runs runs = pauseFreeRuns(pair, speed, pauses, config);
      if (coverage(runs) > coverage(best)) best = std::move(runs);
    }
  }
  return best;
}

}  // namespace

std::vector<std::vector<ReciprocatingRun>> periodicPhases(
    const std::vector<FeatureMatrix>& demos, const std::vector<std::string>& moving,
    const std::vector<std::string>& selected, const std::vector<std::vector<Pause>>& pauses,
    bool contact_sensed, const PeriodicPhaseConfig& config, int threads) {
  if (pauses.size() != demos.size())
    throw std::invalid_argument("periodicPhases: " + std::to_string(demos.size()) + " demos but " +
                                std::to_string(pauses.size()) + " lists of pauses");
  const std::vector<std::string> names =
      selected.empty() ? moving : selectedStates(moving, selected);
  const std::vector<Eigen::MatrixXd> states = scaledStates(demos, names);
  const std::vector<std::string> above_noise =
      contact_sensed ? std::vector<std::string>{}
                     : featuresAboveNoise(demos, moving, config.min_range_sigmas);
  const std::vector<Eigen::MatrixXd> candidates = scaledStates(demos, above_noise);
  std::vector<Runs> out(demos.size());
  parallelFor(demos.size(), threads, [&](std::size_t d) {
    const std::vector<double> clock = demos[d].clock();
    if (names.size() >= 2 && states[d].rows() >= 5)
      out[d] = pauseFreeRuns(states[d], stateSpeed(states[d], clock, config.smoothing), pauses[d],
                             config);
    if (out[d].empty() && above_noise.size() >= 2)
      out[d] = bestPairRuns(candidates[d], clock, pauses[d], config);
  });
  return out;
}

}  // namespace lfd
