// The body of the /segmentation/segment service (lfd_msgs/Segment), separated from the node so
// that it can be tested without a master: bags -> feature matrices -> segmentation pipeline ->
// response. Every failure becomes success=false with an error string; nothing throws.
#pragma once

#include <lfd_msgs/Segment.h>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"
#include "lfd_segmentation/bag_features.hpp"
#include "lfd_segmentation/segmentation_params.hpp"

namespace lfd_segmentation {

/// The node's parameters with the request's non-zero overrides applied (throws
/// std::invalid_argument for an unknown combination or a threshold outside (0,1]).
SegmentationParams applyOverrides(const SegmentationParams& params,
                                  const lfd_msgs::Segment::Request& request);

/// The last request's bags read and features selected (II-B), for the next request on the same
/// bags: an evaluation asks for every combination method in turn, and neither the bags nor the
/// selection depend on the method. Keyed by the bag paths, each file's identity as read (device,
/// inode, size, mtime and ctime in ns: lfd::FileIdentity), and the relevance threshold; anything
/// else may differ between the requests.
struct PreparedCache {
  std::string key;
  std::vector<DemoFeatures> demos;
  std::vector<lfd::FeatureMatrix> matrices;
  lfd::PreparedSegmentation prepared;
};

/// Handles one request; always returns (success=false + error on failure). Before any work: every
/// string within limits/max_request_string_bytes, every path absolute, the request budget. With a
/// cache, a request on the bags of the previous one reuses their features and selection.
void handleSegmentRequest(const SegmentationParams& params,
                          const lfd_msgs::Segment::Request& request,
                          lfd_msgs::Segment::Response& response, PreparedCache* cache = nullptr);

}  // namespace lfd_segmentation
