#include "lfd_segmentation/segment_service.hpp"

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "lfd_core/io/safe_paths.hpp"
#include "lfd_ros/ros_request_strings.hpp"
#include "lfd_segmentation/bag_features.hpp"

namespace lfd_segmentation {

SegmentationParams applyOverrides(const SegmentationParams& params,
                                  const lfd_msgs::Segment::Request& request) {
  SegmentationParams p = params;
  if (!request.combination.empty()) {
    p.pipeline.segmentation.combination = lfd::parseProfileCombination(request.combination);
  }
  if (std::isnan(request.threshold)) throw std::invalid_argument("threshold is NaN");
  if (request.threshold > 0) {
    if (request.threshold > 1) {
      throw std::invalid_argument("threshold T must be in (0,1], got " +
                                  std::to_string(request.threshold));
    }
    p.pipeline.relevance.threshold = request.threshold;
  }
  checkSecondsOverride(request.min_segment_seconds, "min_segment_seconds", params.limits);
  checkSecondsOverride(request.window_seconds, "window_seconds", params.limits);
  if (request.min_segment_seconds > 0) p.min_segment_seconds = request.min_segment_seconds;
  if (request.window_seconds > 0) p.window_seconds = request.window_seconds;
  const std::size_t max_changepoints = p.pipeline.segmentation.max_changepoints;
  if (request.num_changepoints > 0 &&
      static_cast<std::size_t>(request.num_changepoints) > max_changepoints) {
    throw std::invalid_argument("num_changepoints " + std::to_string(request.num_changepoints) +
                                " is over the limit of " + std::to_string(max_changepoints) +
                                " (max_changepoints)");
  }
  if (request.num_changepoints > 0)
    p.pipeline.segmentation.num_changepoints = request.num_changepoints;
  return p;
}

namespace {

// PreparedCache's key: what the bags' features and their selection depend on. Each file is named by
// the identity of the descriptor that is read (device, inode, size, mtime and ctime in ns): a bag
// replaced by a same-size file with the old mtime (touch -r; mv) is another file, never the cache.
std::string cacheKey(const std::vector<DemoFiles>& demos, const SegmentationParams& p) {
  std::ostringstream key;
  key.precision(17);
  key << "T=" << p.pipeline.relevance.threshold;
  for (const DemoFiles& demo : demos) {
    for (std::size_t k = 0; k < demo.parts.size(); ++k)
      key << "|" << demo.names[k] << ":" << demo.parts[k].identity().key();
    key << ";";
  }
  return key.str();
}

// Service requests name absolute paths (the node's working directory is not the caller's), every
// part of a demo written as "a.bag,b.bag" too; the error names the field.
void checkRequestPaths(const std::vector<std::string>& bag_paths, const lfd::PathPolicy& policy) {
  for (std::size_t i = 0; i < bag_paths.size(); ++i) {
    for (const std::string& part : demoParts(bag_paths[i]))
      lfd::checkRequestPath("bag_paths[" + std::to_string(i) + "]", part, policy);
  }
}

lfd_msgs::DemoSegmentation demoMessage(const DemoFeatures& demo,
                                       const lfd::DemoSegmentationResult& r, double rate) {
  lfd_msgs::DemoSegmentation m;
  const lfd::FeatureMatrix& x = demo.matrix;
  m.source = demo.source;
  m.num_samples = static_cast<uint32_t>(r.num_samples);
  m.sample_rate = rate;
  m.start_time = x.timeAt(0);
  m.min_segment_length = static_cast<uint32_t>(r.min_segment_length);
  m.changepoints.assign(r.changepoints.begin(), r.changepoints.end());
  m.changepoint_times = r.changepoint_times;
  m.rejected.assign(r.rejected.begin(), r.rejected.end());
  m.rejected_times = r.rejected_times;
  m.pruned.assign(r.pruned.begin(), r.pruned.end());
  m.pruned_times = r.pruned_times;
  for (const lfd::SplitCandidate& c : r.clasp.candidates) {
    m.candidates.push_back(static_cast<uint32_t>(c.index));
    m.candidate_scores.push_back(c.score);
  }
  m.sensory_events.assign(r.events.begin(), r.events.end());
  const Eigen::Index last = x.rows() - 1;
  for (const lfd::Interval& z : r.zones) {
    lfd_msgs::ConfidenceZone zone;
    zone.begin_index = static_cast<uint32_t>(z.begin);
    zone.end_index = static_cast<uint32_t>(z.end);
    zone.begin_time = x.timeAt(std::min<Eigen::Index>(z.begin, last));
    zone.end_time = x.timeAt(std::min<Eigen::Index>(z.end, last));
    m.zones.push_back(zone);
  }
  return m;
}

// Every string within one bound before anything else: a 10 MB path is refused, not echoed. The
// bag count is checked before the overrides are parsed.
void checkRequestSize(const lfd_msgs::Segment::Request& request, const SegmentationParams& params) {
  lfd::StringBudget strings;
  strings.max_bytes = params.limits.max_request_string_bytes;
  strings.key = "limits/max_request_string_bytes";
  lfd::checkRequestStrings(request, strings);
  if (request.bag_paths.empty()) {
    throw std::invalid_argument("empty request: give at least one bag path");
  }
  if (request.bag_paths.size() > params.limits.max_bags) {
    throw std::invalid_argument(std::to_string(request.bag_paths.size()) +
                                " bag paths, over the limit of " +
                                std::to_string(params.limits.max_bags) + " (limits/max_bags)");
  }
}

// Reads the bags and selects their features unless `cache` already holds them under `key`.
void ensurePrepared(const std::vector<DemoFiles>& files, const std::string& key,
                    const SegmentationParams& p, const lfd::SegmentationPipelineConfig& config,
                    const std::vector<std::string>& bag_paths, PreparedCache& cache) {
  if (!cache.key.empty() && cache.key == key) return;
  cache = PreparedCache{};  // the stale entry goes before anything is read
  for (const DemoFiles& demo : files) {
    cache.demos.push_back(readBagFeatures(demo, p.topics, p.rate, p.limits));
    cache.matrices.push_back(cache.demos.back().matrix);
  }
  checkDemosFit(p, cache.matrices, bag_paths);
  cache.prepared = lfd::prepareSegmentation(cache.matrices, cache.demos[0].sensor_features, config,
                                            cache.demos[0].state_features);
  cache.key = key;
}

lfd_msgs::FeatureScore featureScoreMessage(const lfd::FeatureRelevance& f) {
  lfd_msgs::FeatureScore s;
  s.name = f.name;
  s.mean_correlation = f.mean_correlation;
  s.mean_distance = f.mean_distance;
  s.normalized_distance = f.normalized_distance;
  s.score = f.score;
  s.constant = f.constant;
  s.selected = f.selected;
  s.selected_correlation_only = f.selected_correlation_only;
  s.num_demos = static_cast<uint32_t>(f.correlation.rows());
  for (Eigen::Index r = 0; r < f.correlation.rows(); ++r) {
    for (Eigen::Index c = 0; c < f.correlation.cols(); ++c) {
      s.correlation.push_back(f.correlation(r, c));
    }
  }
  return s;
}

void fillResponse(const std::vector<DemoFeatures>& demos,
                  const lfd::SegmentationPipelineResult& result, double rate,
                  lfd_msgs::Segment::Response& response) {
  response.warnings.clear();
  for (const DemoFeatures& demo : demos)  // the stamps each bag's reader put in order
    response.warnings.insert(response.warnings.end(), demo.warnings.begin(), demo.warnings.end());
  response.warnings.insert(response.warnings.end(), result.warnings.begin(), result.warnings.end());
  response.selected_features = result.selected_features;
  response.selected_weights = result.feature_weights;
  response.sensor_features = result.sensor_features;
  for (std::size_t d = 0; d < demos.size(); ++d) {
    response.demos.push_back(demoMessage(demos[d], result.demos[d], rate));
  }
  if (result.relevance_computed) {
    for (const lfd::FeatureRelevance& f : result.relevance.features) {
      response.features.push_back(featureScoreMessage(f));
    }
  }
}

}  // namespace

void handleSegmentRequest(const SegmentationParams& params,
                          const lfd_msgs::Segment::Request& request,
                          lfd_msgs::Segment::Response& response, PreparedCache* cache) {
  const auto start = std::chrono::steady_clock::now();
  response = lfd_msgs::Segment::Response();
  try {
    checkRequestSize(request, params);
    const SegmentationParams p = applyOverrides(params, request);
    lfd::PathPolicy paths = p.paths;
    paths.require_absolute = true;  // a service: the CLI takes relative paths, the node does not
    checkRequestPaths(request.bag_paths, paths);
    checkRequestBudget(request.bag_paths, p.limits, paths);  // the expanded work, up front
    std::vector<DemoFiles> files;  // opened once: the cache key names what is read
    for (const std::string& path : request.bag_paths) files.push_back(openDemoFiles(path, paths));
    const std::string key = cacheKey(files, p);
    PreparedCache local;  // without a cache
    PreparedCache& used = cache ? *cache : local;
    const lfd::SegmentationPipelineConfig config = p.pipelineConfig();
    ensurePrepared(files, key, p, config, request.bag_paths, used);
    checkDemosFit(p, used.matrices, request.bag_paths);  // this request's window_seconds
    const lfd::SegmentationPipelineResult result =
        lfd::segmentPrepared(used.prepared, used.matrices, config);
    fillResponse(used.demos, result, p.rate, response);
    response.success = true;
  } catch (const std::exception& e) {
    response = lfd_msgs::Segment::Response();
    response.success = false;
    response.error = e.what();
  }
  response.elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace lfd_segmentation
