// The whole segmentation stage of the paper for a set of demonstrations of one task:
//   II-B feature relevance (DTW + correlation) on the state features across demonstrations
//   -> II-C multivariate ClaSP on the selected features of each demonstration, the per-feature
//      profiles weighted by their relevance score and penalized by a Kaiser window
//   -> validation of the changepoints with confidence zones around sensory events (eq. 1),
//      computed from the sensor features only.
// Features have a role: "state" features (poses, velocities, gripper opening...) are candidates
// for segmentation; "sensor" features (touch, wrist force/torque...) only build the zones.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "lfd_core/segmentation/clasp.hpp"
#include "lfd_core/segmentation/feature_relevance.hpp"
#include "lfd_core/segmentation/joint_segmentation_config.hpp"
#include "lfd_core/segmentation/multivariate_segmentation.hpp"
#include "lfd_core/segmentation/sensory_events.hpp"
#include "lfd_core/segmentation/time_series.hpp"

namespace lfd {

/// Every time parameter of the segmentation, in seconds. When set in SegmentationPipelineConfig,
/// the pipeline converts them to samples for each demonstration with that demonstration's own
/// sample rate (median step of its clock), so one configuration holds at any recording rate.
/// Rounded to the nearest sample; a window/lag/gap never drops below what the algorithm needs (>= 1
/// sample, windows >= 2, the median window odd).
struct TimeParameters {
  double min_segment = 1.0;    ///< min_s (s); 0 = automatic (max(2 * largest window, n / 20))
  double window = 0.0;         ///< fixed ClaSP window for every feature (s); 0 = automatic
  double min_window = 0.2;     ///< lower bound of the automatic ClaSP windows (s)
  double event_median = 0.26;  ///< running-median window of the sensor signals (s)
  double event_difference_lag = 0.5;  ///< lag of the level difference (s)
  double event_merge_gap = 1.0;       ///< bursts closer than this merge (s)
  double event_min_active = 0.0;      ///< bursts shorter than this are ignored (s)
  double event_noise_block = 1.0;     ///< block length of the local noise estimate (s)
};

/// How ClaSP's candidates meet the sensory zones: the name of the SegmentationMethod that
/// segmentPrepared runs (segmentation_method.hpp; toString gives the registry name).
enum class SegmentationProcedure {
  /// Ours: the zones first, each recursion step takes its argmax inside them, the changepoint
  /// sits on a sensory event of its zone (anchor_to_events), the demos agree on their count
  /// (consensus_count).
  kZoneSearch,
  /// The paper's (II-C, Fig. 8): `paper_candidates` candidates anywhere from the recursive,
  /// Kaiser-penalized combined profile, then the zone filter (eq. 1): those inside a zone are
  /// the changepoints.
  kPaper,
  /// All demos together (joint_segmentation.hpp): evidence of every kind (contact, sensor level
  /// steps, motion after a pause, ClaSP) agreed across the demos aligned by DTW.
  kJoint,
};

/// "zone_search", "paper" or "joint" (throws std::invalid_argument otherwise).
SegmentationProcedure parseSegmentationProcedure(const std::string& name);
std::string toString(SegmentationProcedure procedure);

struct SegmentationPipelineConfig {
  /// Time parameters in seconds (see TimeParameters); when unset, the sample counts of
  /// `segmentation`, `window_size` and `events` are used as they are (index-only series).
  std::optional<TimeParameters> seconds;
  /// II-B threshold T and DTW settings.
  FeatureRelevanceConfig relevance;
  /// II-C combination, ClaSP settings, Kaiser beta. Its min_segment_length (min_s, samples; 0 =
  /// automatic), window_sizes and num_changepoints are the per-request overrides.
  MultivariateSegmentationConfig segmentation;
  /// Fixed ClaSP window for every selected feature (0 = automatic per feature).
  std::size_t window_size = 0;
  /// Sensory events and eq. (1) zones.
  SensoryEventConfig events;
  /// false: every ClaSP changepoint is accepted (no sensor validation).
  bool validate_with_sensors = true;
  /// How candidates meet zones (needs validate_with_sensors; without sensors ClaSP's
  /// changepoints are taken as they are).
  SegmentationProcedure procedure = SegmentationProcedure::kZoneSearch;
  /// kPaper: the number of candidates the recursion proposes (no significance test; fewer when
  /// the ranges are too short for min_s). The paper's Fig. 8 shows five.
  std::size_t paper_candidates = 5;
  /// kZoneSearch: each changepoint sits on the sensory event of its zone nearest to ClaSP's
  /// in-zone argmax, rest edges first (MultivariateSegmentationConfig::zone_anchors).
  bool anchor_to_events = true;
  /// Demonstrations of one task hold the same skills: when the most common count K of validated
  /// changepoints is held by at least 3 voting demos and by more than any other count, a demo
  /// with more keeps its K most significant ones and reports the others as `pruned` (a hesitation
  /// mid-skill is then not a skill boundary). With sensor validation only demos with a sensory
  /// event vote.
  bool consensus_count = true;
  /// With consensus_count and sensor validation: a demo with fewer than K changepoints takes its
  /// best in-zone candidates down to this p-value (0 = never), one per free zone: the agreement
  /// of the other demos is evidence that a skill boundary is there.
  double consensus_fill_p_value = 0.0;
  /// kJoint: evidence weights, pauses, alignment and agreement.
  JointSegmentationConfig joint;
  /// Worker threads for DTW and the per-demonstration segmentations (<= 0 = all cores).
  int threads = 0;
};

/// Each sensor column's sensor: the channels of one sensor share their name up to the last '/'
/// (a topic's array or vector: /touch/values/0 and /touch/values/1); names without '/' (CSV
/// columns) are one sensor.
std::vector<std::size_t> sensorChannelGroups(const std::vector<std::string>& names);

/// The configuration with its seconds (if any) converted to sample counts at `rate` (Hz) and
/// `seconds` cleared; unchanged without seconds. Throws std::invalid_argument for rate <= 0.
SegmentationPipelineConfig inSamples(const SegmentationPipelineConfig& config, double rate);

/// Sample rate (Hz) of a demonstration's clock: 1 / median step. Throws std::invalid_argument when
/// the demonstration has no clock (no timestamps) or a non-increasing one.
double sampleRateOf(const FeatureMatrix& demo);

struct DemoSegmentationResult {
  std::vector<std::size_t> changepoints;  ///< validated changepoints (row indices, sorted)
  std::vector<double> changepoint_times;  ///< their times (s, or index without a clock)
  /// kJoint: the kinds of evidence of each changepoint in this demo ("contact+clasp", ...).
  std::vector<std::string> changepoint_evidence;
  std::vector<std::size_t> rejected;  ///< ClaSP changepoints outside every zone
  std::vector<double> rejected_times;
  std::vector<std::size_t> pruned;  ///< validated, dropped to the consensus count (consensus_count)
  std::vector<double> pruned_times;
  /// In-zone candidates accepted because the other demos agree on more changepoints
  /// (consensus_fill_p_value); also in `changepoints`.
  std::vector<std::size_t> added;
  std::vector<double> added_times;
  std::vector<Interval> zones;  ///< confidence zones (row indices, closed)
  /// kJoint: where the state features rest ([first, last] row at rest, closed), the demo's
  /// first and last rest included: a boundary between skills is often inside one.
  std::vector<Interval> pauses;
  std::vector<std::size_t> events;          ///< sensory events (row indices)
  std::vector<SensoryEvent> event_details;  ///< the same with rest edges and strengths
  std::size_t min_segment_length = 0;       ///< the min_s used for ClaSP and the zones
  std::size_t num_samples = 0;
  double sample_rate = 0.0;        ///< Hz of the demonstration's clock (0 = index-only series)
  MultivariateSegmentation clasp;  ///< candidates, windows, profiles (paper Fig. 5, 8)
};

struct SegmentationPipelineResult {
  std::vector<DemoSegmentationResult> demos;   ///< in input order
  std::vector<std::string> state_features;     ///< features considered for segmentation
  std::vector<std::string> sensor_features;    ///< features used for the zones
  std::vector<std::string> selected_features;  ///< used by ClaSP (best first)
  std::vector<double> feature_weights;         ///< combination weight of each selected feature
  bool relevance_computed = false;             ///< false with a single demonstration
  FeatureRelevanceResult relevance;            ///< both variants, per-feature N x N matrices
  std::vector<std::string> warnings;
  double relevance_seconds = 0;     ///< wall time of II-B (DTW + correlations)
  double segmentation_seconds = 0;  ///< wall time of II-C (ClaSP + validation, all demos)
};

/// The part of the pipeline that does not depend on the combination method nor on any II-C
/// setting: input checks, constant features, II-B feature relevance. `base` holds everything of
/// the result but the demos.
struct PreparedSegmentation {
  SegmentationPipelineResult base;
};

/// Checks and II-B of runSegmentationPipeline (same arguments, same errors).
PreparedSegmentation prepareSegmentation(const std::vector<FeatureMatrix>& demos,
                                         const std::vector<std::string>& sensor_features,
                                         const SegmentationPipelineConfig& config = {},
                                         const std::vector<std::string>& state_features = {});

/// II-C on prepared demos by the method config.procedure names (makeSegmentationMethod):
/// `config` may differ from the one prepared with in its II-C settings only (combination, ClaSP,
/// events, procedure), e.g. to compare the combinations on one feature selection. `demos` must be
/// the prepared ones.
SegmentationPipelineResult segmentPrepared(const PreparedSegmentation& prepared,
                                           const std::vector<FeatureMatrix>& demos,
                                           const SegmentationPipelineConfig& config = {});

/// Warns, per demo, of each constant (dead) sensor and of a demo without a sensory event
/// (nothing when the sensors were not used).
void addSensorWarnings(const std::vector<FeatureMatrix>& demos, bool validated,
                       SegmentationPipelineResult* result);

/// Runs the pipeline (prepareSegmentation, then segmentPrepared). `sensor_features` name the
/// sensor columns; `state_features` name the candidates for segmentation (empty = every column that
/// is not a sensor). Every demonstration must have the same set of features (any column order).
/// Throws std::invalid_argument (with the demonstration and feature named) for: no
/// demonstrations, features that differ between demonstrations, unknown feature names, NaN/Inf
/// samples, empty demonstrations, demonstrations shorter than 2 * min_s, no state feature, or
/// only constant state features. A single demonstration falls back to every non-constant state
/// feature with equal weights (warning); constant features are left out (warning).
SegmentationPipelineResult runSegmentationPipeline(
    const std::vector<FeatureMatrix>& demos, const std::vector<std::string>& sensor_features,
    const SegmentationPipelineConfig& config = {},
    const std::vector<std::string>& state_features = {});

}  // namespace lfd
