// Procedure "zone_search" (zone_search_segmentation.hpp).
#include "lfd_core/segmentation/zone_search_segmentation.hpp"

#include "lfd_core/segmentation/segmentation_consensus.hpp"
#include "lfd_core/segmentation/segmentation_steps.hpp"

namespace lfd {
namespace {

// ClaSP searches only the zones, which depend on its min_s (eq. 1). The anchors place each
// changepoint on a sensory event: the sensors time an interaction to a few samples, while the
// smooth kinematics ClaSP segments peak up to a window away from it.
void search_in_zones(const DemoEvidence& evidence, bool anchor_to_events,
                     MultivariateSegmentationConfig* clasp) {
  clasp->candidate_zones_for = [&evidence](std::size_t min_s) { return evidence.zones(min_s); };
  if (!anchor_to_events) return;
  for (const SensoryEvent& e : evidence.events.details) {
    clasp->zone_anchors.push_back(e.index);
    clasp->preferred_anchors.push_back(e.rest_edge);
  }
}

DemoSegmentationResult segment_demo(const FeatureMatrix& demo, const DemoSettings& settings,
                                    const PerDemoRun& run) {
  const DemoEvidence evidence = detect_demo_evidence(demo, settings, run);
  MultivariateSegmentationConfig clasp = clasp_settings(settings, run.result);
  if (run.validate) search_in_zones(evidence, settings.config.anchor_to_events, &clasp);
  DemoSegmentationResult out = run_demo_clasp(demo, settings, run.result, clasp);
  validate_changepoints(evidence, run.validate, &out);
  add_changepoint_times(demo, &out);
  return out;
}

}  // namespace

SegmentationPipelineResult ZoneSearchSegmentation::segment(
    const PreparedSegmentation& prepared, const std::vector<FeatureMatrix>& demos,
    const SegmentationPipelineConfig& config) const {
  PerDemoRun run = begin_per_demo_run(prepared, demos, config);
  for_each_demo(demos.size(), config.threads, [&](std::size_t d) {
    run.result.demos[d] = segment_demo(demos[d], run.settings[d], run);
  });
  if (config.consensus_count)
    agree_on_changepoint_count(demos, run.validate, config.consensus_fill_p_value, &run.result);
  return finish_per_demo_run(demos, &run);
}

}  // namespace lfd
