// JSON rendering of a segmentation result (the `segment` CLI output, also used for figures):
// changepoints, candidates, zones, selected features, both relevance variants, per-feature
// correlation matrices and the combined ClaSP profiles. NaN profile entries become null.
// Optionally the feature matrices the segmentation read, which the figures draw.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "lfd_core/io/safe_paths.hpp"
#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd_segmentation {

/// The `segment` CLI's result file: "format" marks it as lfd's (its --output replaces only such a
/// file); files written before the marker are recognised by their top-level "success" and "mode"
/// or "error".
constexpr const char* kSegmentationResultFormat = "lfd_segmentation_result";
lfd::OutputKind segmentationResultOutput();

struct JsonOptions {
  bool profiles = true;           ///< combined profile (raw and Kaiser-penalized) per demo
  bool feature_profiles = false;  ///< every selected feature's own profile (large)
};

nlohmann::json toJson(const lfd::SegmentationPipelineResult& result,
                      const std::vector<lfd::FeatureMatrix>& demos,
                      const std::vector<std::string>& sources, const JsonOptions& options = {});

/// Plain multivariate ClaSP of one series (no relevance, no validation).
nlohmann::json toJson(const lfd::MultivariateSegmentation& segmentation,
                      const lfd::FeatureMatrix& demo, const std::string& source,
                      const JsonOptions& options = {});

/// What the segmentation read, one entry per demo in input order (`segment --features`, drawn by
/// plot_segmentation.py): "time", the demo's clock (s, full precision, the clock of the
/// changepoint times), and "features", each with its "name", "role" (state: in `states`, sensor:
/// in `sensors`, else context) and "values". A value is rounded to a decimal multiple of at most
/// kFeatureResolution of its feature's range (of its magnitude when constant): far below a
/// figure's pixel, and half the bytes of full doubles.
constexpr double kFeatureResolution = 1e-6;
nlohmann::json featureMatricesJson(const std::vector<lfd::FeatureMatrix>& demos,
                                   const std::vector<std::string>& states,
                                   const std::vector<std::string>& sensors);

/// The JSON as text, indented one space per level, except that arrays of numbers or strings stay
/// on one line: profiles and feature values would otherwise take a line per number.
std::string dumpJson(const nlohmann::json& json);

}  // namespace lfd_segmentation
