// Procedure "paper" (paper_segmentation.hpp).
#include "lfd_core/segmentation/paper_segmentation.hpp"

#include "lfd_core/segmentation/segmentation_steps.hpp"

namespace lfd {
namespace {

DemoSegmentationResult segmentDemo(const FeatureMatrix& demo, const DemoSettings& settings,
                                   const PerDemoRun& run) {
  const DemoEvidence evidence = detectDemoEvidence(demo, settings, run);
  MultivariateSegmentationConfig clasp = claspSettings(settings, run.result);
  // The paper asks ClaSP for a fixed number of candidates (no significance test): the zone
  // filter, not ClaSP, decides which are changepoints. Without sensors ClaSP's test decides.
  if (run.validate) clasp.num_changepoints = static_cast<int>(settings.config.paper_candidates);
  DemoSegmentationResult out = runDemoClasp(demo, settings, run.result, clasp);
  validateChangepoints(evidence, run.validate, &out);
  addChangepointTimes(demo, &out);
  return out;
}

}  // namespace

SegmentationPipelineResult PaperSegmentation::segment(
    const PreparedSegmentation& prepared, const std::vector<FeatureMatrix>& demos,
    const SegmentationPipelineConfig& config) const {
  PerDemoRun run = beginPerDemoRun(prepared, demos, config);
  forEachDemo(demos.size(), config.threads, [&](std::size_t d) {
    run.result.demos[d] = segmentDemo(demos[d], run.settings[d], run);
  });
  return finishPerDemoRun(demos, &run);
}

}  // namespace lfd
