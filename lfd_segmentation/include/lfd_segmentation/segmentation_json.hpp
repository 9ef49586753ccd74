// JSON rendering of a segmentation result (the `segment` CLI output, also used for figures):
// changepoints, candidates, zones, selected features, both relevance variants, per-feature
// correlation matrices and the combined ClaSP profiles. NaN profile entries become null.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "lfd_core/segmentation_pipeline.hpp"

namespace lfd_segmentation {

struct JsonOptions {
  bool profiles = true;           ///< combined profile (raw and Kaiser-penalized) per demo
  bool feature_profiles = false;  ///< every selected feature's own profile (large)
};

nlohmann::json to_json(const lfd::SegmentationPipelineResult& result,
                       const std::vector<lfd::FeatureMatrix>& demos,
                       const std::vector<std::string>& sources, const JsonOptions& options = {});

/// Plain multivariate ClaSP of one series (no relevance, no validation).
nlohmann::json to_json(const lfd::MultivariateSegmentation& segmentation,
                       const lfd::FeatureMatrix& demo, const std::string& source,
                       const JsonOptions& options = {});

}  // namespace lfd_segmentation
