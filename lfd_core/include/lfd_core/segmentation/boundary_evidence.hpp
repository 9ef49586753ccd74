// Evidence of a skill boundary in one demonstration, of every kind the joint segmentation weighs
// (joint_segmentation.hpp): a sensor that makes or loses contact, a sensor level that steps while
// in contact, the hand resuming motion after a pause, and ClaSP's own changepoints. Each piece is
// an instant with a weight in (0, 1]: how sure that kind of evidence alone is that a boundary is
// there. The joint segmentation adds them up across kinds (noisy-OR) and across demonstrations.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "lfd_core/segmentation/multivariate_segmentation.hpp"
#include "lfd_core/segmentation/reciprocating_motion.hpp"
#include "lfd_core/segmentation/sensory_events.hpp"

namespace lfd {

enum class EvidenceKind {
  kContact,      ///< a sensor leaves its rest level or regains it (contact made or lost)
  kSensorLevel,  ///< a sensor's level steps while away from rest (a snap, a press that deepens)
  kMotionOnset,  ///< the state features move again after a pause
  kMotionStop,   ///< the state features stop for an instant (one motion ends, the next begins)
  kRhythm,       ///< a periodic back-and-forth motion begins or ends (reciprocating_motion.hpp)
  kClasp,        ///< a changepoint of ClaSP's recursive segmentation (shape change)
};

std::string toString(EvidenceKind kind);

struct BoundaryEvidence {
  std::size_t index = 0;  ///< sample of the demonstration
  double weight = 0.0;    ///< (0, 1]
  EvidenceKind kind = EvidenceKind::kClasp;
};

/// Weights of each kind (the joint segmentation's `evidence` settings). A kind's weight is the
/// support it alone gives a boundary; the consensus accepts a boundary whose support, averaged
/// over the demos, reaches JointSegmentationConfig::min_support.
struct EvidenceWeights {
  double contact = 0.9;  ///< rest edges: the sensors say an interaction starts or ends
  /// A level step in contact (each end of one ramp weighs less: sensoryEvidence).
  double sensor_level = 0.7;
  double motion_onset = 0.8;  ///< motion after a long pause, scaled by pause and motion below
  /// An instant of rest between two motions: weak alone (every reversal of a periodic motion is
  /// one), it marks where a shape change ClaSP finds nearby begins.
  double motion_stop = 0.3;
  double clasp = 0.5;  ///< a ClaSP changepoint (significant by ClaSP's own test)
  /// A periodic phase (grating, sawing, stroking) begins or ends: the only sign of it in a
  /// pose-only recording, where every reversal inside is an instant of rest.
  double rhythm = 0.6;
};

/// How pauses of the state features are found (all in seconds or as statistics).
struct PauseConfig {
  /// Speed is the norm of the state features' time derivatives, each feature divided by its
  /// range over the task, smoothed by a Gaussian of this sigma (s).
  double smoothing = 0.1;
  /// At rest below this fraction of the demo's 95th percentile speed.
  double rest_fraction = 0.05;
  /// Pauses shorter than this are velocity zero crossings of a reversal, not pauses (s).
  double min_pause = 0.25;
  /// A pause of duration p weighs 1 - exp(-p / pause_scale): a hesitation of 0.3 s little, a
  /// pause of 2 s (the operator waiting for the next step) nearly fully.
  double pause_scale = 1.0;
  /// The motion after the pause weighs min(1, its peak speed within this window (s) /
  /// (full_motion_fraction x the demo's 95th percentile speed)): a small readjustment within a
  /// pause is no new skill, a motion as fast as half the demo's fast ones is.
  double motion_window = 2.0;
  double full_motion_fraction = 0.5;
  /// A bout of motion between two rests whose peak stays below this fraction of the 95th
  /// percentile speed belongs to the pause (a compliant arm settling as its gripper closes).
  double small_motion_fraction = 0.3;
};

/// A pause: samples [begin, end) at rest; `end` is where the motion resumes (== the demo's
/// length for the final rest).
struct Pause {
  std::size_t begin = 0;
  std::size_t end = 0;
};

/// The pauses of a speed profile (speed >= 0, on the demo's clock `time`).
std::vector<Pause> findPauses(const Eigen::VectorXd& speed, const std::vector<double>& time,
                              const PauseConfig& config);

/// Speed profile of the state features (rows = samples, cols = features already divided by their
/// task-wide range) on the demo's clock `time` (s). Throws std::invalid_argument on a size
/// mismatch.
Eigen::VectorXd stateSpeed(const Eigen::MatrixXd& scaled_states, const std::vector<double>& time,
                           double smoothing_seconds);

/// Each feature's velocity as stateSpeed sees it (smoothed, central differences): stateSpeed is
/// the norm of a row, and the speed of any subset of the features the norm of its columns.
Eigen::MatrixXd stateVelocities(const Eigen::MatrixXd& scaled_states,
                                const std::vector<double>& time, double smoothing_seconds);

/// A demo's typical speed, the unit of every rest and motion threshold: the 95th percentile of
/// its speed profile (its moves' peaks, not one spike's). 0 for an empty profile.
double typicalSpeed(const Eigen::VectorXd& speed);

/// Evidence of motion onsets after the pauses (not the first motion of the demo: it starts at
/// rest).
std::vector<BoundaryEvidence> motionOnsetEvidence(const Eigen::VectorXd& speed,
                                                  const std::vector<double>& time,
                                                  const std::vector<Pause>& pauses,
                                                  const PauseConfig& config, double weight);

/// Evidence of the instants of rest shorter than a pause between two motions (at the speed's
/// minimum).
std::vector<BoundaryEvidence> motionStopEvidence(const Eigen::VectorXd& speed,
                                                 const std::vector<double>& time,
                                                 const PauseConfig& config, double weight);

/// A pause between two motions is one transition: evidence inside it (the gripper closing while
/// the arm waits) moves to the pause's end, where the next motion starts. Evidence within
/// `start_samples` of the pause's beginning stays: a contact made as the hand stops (a press
/// held still) begins a phase. Evidence in the first rest or the last one stays where it is.
void gatherIntoPauses(const std::vector<Pause>& pauses, std::size_t samples,
                      std::size_t start_samples, std::vector<BoundaryEvidence>* evidence);

/// Evidence of the sensory events: rest edges as contact, the others as level steps. A level
/// event within `fold_samples` of a rest edge that changes the level the way the edge does (away
/// from rest after contact is made, towards it before contact is lost) is that contact's own
/// force building up or fading (the ramp reaching its plateau), so it joins the rest edge instead
/// of standing alone. One that goes the other way joins it only within `reversal_fold_samples`
/// (a press overshooting as it lands): further off it is a phase of its own, as an insertion's
/// force rising before a snap whose drop ends within the sensor's rest band. The start and the
/// end of one ramp (SensoryEvent::ramp_end) left standing are one change: each weighs
/// 1 - sqrt(1 - sensor_level), the two together (noisy-OR) one step's weight.
std::vector<BoundaryEvidence> sensoryEvidence(const SensorEvents& events,
                                              const EvidenceWeights& weights,
                                              std::size_t fold_samples,
                                              std::size_t reversal_fold_samples);

/// Evidence of the periodic phases' edges. An edge within `fold_samples` of a contact (a rest
/// edge in `contacts`) is that contact's own: the strokes of a wipe start a little after the press
/// and stop a little before the lift, and the skill is the contact's.
std::vector<BoundaryEvidence> rhythmEvidence(const std::vector<ReciprocatingRun>& runs,
                                             const std::vector<BoundaryEvidence>& contacts,
                                             double weight, std::size_t fold_samples);

/// Evidence of ClaSP's accepted changepoints.
std::vector<BoundaryEvidence> claspEvidence(const MultivariateSegmentation& clasp, double weight);

}  // namespace lfd
