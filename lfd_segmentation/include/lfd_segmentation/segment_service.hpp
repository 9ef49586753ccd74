// The body of the /segmentation/segment service (lfd_msgs/Segment), separated from the node so
// that it can be tested without a master: bags -> feature matrices -> segmentation pipeline ->
// response. Every failure becomes success=false with an error string; nothing throws.
#pragma once

#include <lfd_msgs/Segment.h>

#include "lfd_segmentation/segmentation_params.hpp"

namespace lfd_segmentation {

/// The node's parameters with the request's non-zero overrides applied (throws
/// std::invalid_argument for an unknown combination or a threshold outside (0,1]).
SegmentationParams apply_overrides(const SegmentationParams& params,
                                   const lfd_msgs::Segment::Request& request);

/// Handles one request; always returns (success=false + error on failure).
void handle_segment_request(const SegmentationParams& params,
                            const lfd_msgs::Segment::Request& request,
                            lfd_msgs::Segment::Response& response);

}  // namespace lfd_segmentation
