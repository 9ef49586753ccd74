// Settings of the joint segmentation (joint_segmentation.hpp), in seconds or as statistics.
#pragma once

#include "lfd_core/segmentation/boundary_evidence.hpp"

namespace lfd {

struct JointSegmentationConfig {
  EvidenceWeights weights;
  PauseConfig pauses;
  /// Step of the grid the demos are aligned on (s): alignment needs the phases' order, not the
  /// samples; each boundary is then placed on its own demo's evidence at the full rate.
  double grid_step = 0.1;
  /// The alignment's warp stays within this fraction of the longer demo of the straight line
  /// from start to end (>= 1: unconstrained): a periodic phase with a different number of
  /// strokes otherwise lets DTW fold whole phases onto one stroke.
  double alignment_band = 0.2;
  /// Spread of a piece of evidence on the reference's axis (s, Gaussian sigma) when a demo's
  /// boundary is placed: the DTW alignment's error between demos that move at different speeds.
  double spread = 0.5;
  /// The same spread when the demos' evidence is added up into the support of a boundary (s).
  /// Narrower than `spread`: two changes 0.8 s apart (a snap-fit's insertion and its snap) must
  /// stay two peaks, not one plateau whose top lies between them and takes a piece of either.
  double agreement_spread = 0.35;
  /// A boundary of the task needs this support: the mean over the demos of each demo's evidence
  /// near it (noisy-OR of its pieces). 0.5 = as if half the demos were sure of it.
  double min_support = 0.5;
  /// A boundary closer than min_segment (s) to a better supported one needs this support: short
  /// phases exist, but two pieces of evidence of one change (a touch and the force settling)
  /// usually lie that close.
  double short_phase_support = 0.8;
  /// A demo's own evidence must lie within this of an agreed boundary (s, on the reference's
  /// axis); a demo with none there is reported as lacking that boundary, never forced.
  double match_window = 1.5;
  /// The sensory events' merge gap for this procedure (s; 0 = events/merge_gap_seconds): the
  /// agreement across demos, not a second of rest, tells a contact from chatter, so a stroke that
  /// lifts off for 0.8 s is a contact of its own.
  double event_merge_gap = 0.5;
  /// A sensor level step within this of a rest edge (s) that goes the edge's way is that
  /// contact's own force building up or fading, and joins the rest edge (one going the other way
  /// joins it within `colocation` only: boundary_evidence.hpp, sensoryEvidence).
  double ramp_fold = 1.0;
  /// A contact sensor that repeats one reading on all its channels for this long (s), while it
  /// repeats none in most demos (it has noise), did not measure then: its events within a lag
  /// of that stretch are not used (stale_readings.hpp). 0 = off.
  double stale_reading = 0.5;
  /// Where a demo's contact sensor did not measure near a boundary, the boundary is placed by the
  /// motion within this (s) on either side of it in the demos whose sensor did (motion_match.hpp).
  double motion_match_window = 1.0;
  /// The grid step of that match (s): finer than grid_step, since it places a boundary.
  double motion_match_step = 0.02;
  /// Where no contact sensor is there and the features II-B selected show no periodic phase,
  /// pairs of the features moving at least this many noise sigmas are searched for one
  /// (periodic_phases.hpp).
  double rhythm_min_range_sigmas = 20.0;
  /// A demo's own evidence for a boundary must be at least this sure (as an instant of rest): a
  /// hesitation is no boundary, even where the other demos have one.
  double min_piece_weight = 0.3;
  /// Pieces of one demo's evidence closer than this (s) mark one instant: they reinforce each
  /// other when a boundary is placed, and are claimed by it together. A level step reversing a
  /// rest edge this near it is at the edge's instant.
  double colocation = 0.25;
  /// A sensor whose magnitude correlates with the robot's speed above this (pooled over the
  /// demos) reports the robot's own motion (a tracking error, inertia), not contact: its events
  /// are left out.
  double max_speed_correlation = 0.4;
  /// A demo's unmatched evidence at least this heavy is reported as an event its siblings lack.
  double extra_event_weight = 0.85;
};

}  // namespace lfd
