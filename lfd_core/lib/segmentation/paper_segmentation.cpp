// Procedure "paper" (paper_segmentation.hpp).
#include "lfd_core/segmentation/paper_segmentation.hpp"

#include "lfd_core/segmentation/segmentation_steps.hpp"

namespace lfd {
namespace {

DemoSegmentationResult segment_demo(const FeatureMatrix& demo, const DemoSettings& settings,
                                    const PerDemoRun& run) {
  const DemoEvidence evidence = detect_demo_evidence(demo, settings, run);
  MultivariateSegmentationConfig clasp = clasp_settings(settings, run.result);
  // The paper asks ClaSP for a fixed number of candidates (no significance test): the zone
  // filter, not ClaSP, decides which are changepoints. Without sensors ClaSP's test decides.
  if (run.validate) clasp.num_changepoints = static_cast<int>(settings.config.paper_candidates);
  DemoSegmentationResult out = run_demo_clasp(demo, settings, run.result, clasp);
  validate_changepoints(evidence, run.validate, &out);
  add_changepoint_times(demo, &out);
  return out;
}

}  // namespace

SegmentationPipelineResult PaperSegmentation::segment(
    const PreparedSegmentation& prepared, const std::vector<FeatureMatrix>& demos,
    const SegmentationPipelineConfig& config) const {
  PerDemoRun run = begin_per_demo_run(prepared, demos, config);
  for_each_demo(demos.size(), config.threads, [&](std::size_t d) {
    run.result.demos[d] = segment_demo(demos[d], run.settings[d], run);
  });
  return finish_per_demo_run(demos, &run);
}

}  // namespace lfd
