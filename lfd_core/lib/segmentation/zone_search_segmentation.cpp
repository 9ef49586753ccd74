// Procedure "zone_search" (zone_search_segmentation.hpp).
#include "lfd_core/segmentation/zone_search_segmentation.hpp"

#include "lfd_core/segmentation/segmentation_consensus.hpp"
#include "lfd_core/segmentation/segmentation_steps.hpp"

namespace lfd {
namespace {

// ClaSP searches only the zones, which depend on its min_s (eq. 1). The anchors place each
// changepoint on a sensory event: the sensors time an interaction to a few samples, while the
// smooth kinematics ClaSP segments peak up to a window away from it.
void searchInZones(const DemoEvidence& evidence, bool anchor_to_events,
                   MultivariateSegmentationConfig* clasp) {
  clasp->candidate_zones_for = [&evidence](std::size_t min_s) { return evidence.zones(min_s); };
  if (!anchor_to_events) return;
  for (const SensoryEvent& e : evidence.events.details) {
    clasp->zone_anchors.push_back(e.index);
    clasp->preferred_anchors.push_back(e.rest_edge);
  }
}

DemoSegmentationResult segmentDemo(const FeatureMatrix& demo, const DemoSettings& settings,
                                   const PerDemoRun& run) {
  const DemoEvidence evidence = detectDemoEvidence(demo, settings, run);
  MultivariateSegmentationConfig clasp = claspSettings(settings, run.result);
  if (run.validate) searchInZones(evidence, settings.config.anchor_to_events, &clasp);
  DemoSegmentationResult out = runDemoClasp(demo, settings, run.result, clasp);
  validateChangepoints(evidence, run.validate, &out);
  addChangepointTimes(demo, &out);
  return out;
}

}  // namespace

SegmentationPipelineResult ZoneSearchSegmentation::segment(
    const PreparedSegmentation& prepared, const std::vector<FeatureMatrix>& demos,
    const SegmentationPipelineConfig& config) const {
  PerDemoRun run = beginPerDemoRun(prepared, demos, config);
  forEachDemo(demos.size(), config.threads, [&](std::size_t d) {
    run.result.demos[d] = segmentDemo(demos[d], run.settings[d], run);
  });
  if (config.consensus_count)
    agreeOnChangepointCount(demos, run.validate, config.consensus_fill_p_value, &run.result);
  return finishPerDemoRun(demos, &run);
}

}  // namespace lfd
