#include "lfd_core/segmentation/segmentation_pipeline.hpp"

#include "lfd_core/segmentation/segmentation_method.hpp"
#include "lfd_core/segmentation/segmentation_steps.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lfd {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out;
}

// Every demonstration must carry the same feature names (in any order).
void checkSameFeatures(const std::vector<FeatureMatrix>& demos) {
  const std::set<std::string> reference(demos[0].names.begin(), demos[0].names.end());
  if (reference.size() != demos[0].names.size()) {
    throw std::invalid_argument(demoLabel(0) + " has duplicate feature names");
  }
  for (std::size_t d = 1; d < demos.size(); ++d) {
    const std::set<std::string> names(demos[d].names.begin(), demos[d].names.end());
    if (names.size() != demos[d].names.size()) {
      throw std::invalid_argument(demoLabel(d) + " has duplicate feature names");
    }
    if (names == reference) continue;
    std::vector<std::string> missing, extra;
    std::set_difference(reference.begin(), reference.end(), names.begin(), names.end(),
                        std::back_inserter(missing));
    std::set_difference(names.begin(), names.end(), reference.begin(), reference.end(),
                        std::back_inserter(extra));
    std::string msg = "features differ between demonstrations: " + demoLabel(d);
    if (!missing.empty()) msg += " lacks " + join(missing);
    if (!extra.empty()) msg += (missing.empty() ? " has extra " : " and has extra ") + join(extra);
    throw std::invalid_argument(msg + " (compared with " + demoLabel(0) + ")");
  }
}

bool isConstant(const FeatureMatrix& demo, int col) {
  const double lo = demo.data.col(col).minCoeff(), hi = demo.data.col(col).maxCoeff();
  return !(hi - lo > 1e-12 * (1.0 + std::max(std::abs(hi), std::abs(lo))));
}

}  // namespace

std::vector<std::size_t> sensorChannelGroups(const std::vector<std::string>& names) {
  std::map<std::string, std::size_t> ids;
  std::vector<std::size_t> groups;
  for (const std::string& name : names) {
    const std::size_t slash = name.rfind('/');
    const std::string sensor = slash == std::string::npos ? "" : name.substr(0, slash);
    groups.push_back(ids.emplace(sensor, ids.size()).first->second);
  }
  return groups;
}

namespace {
std::size_t samples(double seconds, double rate, std::size_t at_least) {
  return std::max<std::size_t>(at_least, static_cast<std::size_t>(std::lround(seconds * rate)));
}
}  // namespace

SegmentationProcedure parseSegmentationProcedure(const std::string& name) {
  if (name == "zone_search") return SegmentationProcedure::kZoneSearch;
  if (name == "paper") return SegmentationProcedure::kPaper;
  if (name == "joint") return SegmentationProcedure::kJoint;
  throw std::invalid_argument("unknown segmentation procedure '" + name +
                              "' (zone_search, paper, joint)");
}

std::string toString(SegmentationProcedure procedure) {
  switch (procedure) {
    case SegmentationProcedure::kPaper:
      return "paper";
    case SegmentationProcedure::kJoint:
      return "joint";
    case SegmentationProcedure::kZoneSearch:
      break;
  }
  return "zone_search";
}

SegmentationPipelineConfig inSamples(const SegmentationPipelineConfig& config, double rate) {
  SegmentationPipelineConfig s = config;
  if (!config.seconds) return s;
  if (!(rate > 0) || !std::isfinite(rate))
    throw std::invalid_argument("sample rate must be > 0, got " + std::to_string(rate));
  const TimeParameters& t = *config.seconds;
  s.segmentation.min_segment_length = t.min_segment > 0 ? samples(t.min_segment, rate, 1) : 0;
  s.window_size = t.window > 0 ? samples(t.window, rate, 2) : 0;
  s.segmentation.clasp.min_window = samples(t.min_window, rate, 2);
  s.events.median_window = samples(t.event_median, rate, 1) | 1;  // odd: a centred median
  s.events.difference_lag = samples(t.event_difference_lag, rate, 1);
  s.events.merge_gap = samples(t.event_merge_gap, rate, 0);
  s.events.min_active_samples = samples(t.event_min_active, rate, 1);
  s.events.noise_block = samples(t.event_noise_block, rate, 4);
  s.seconds.reset();
  return s;
}

double sampleRateOf(const FeatureMatrix& demo) {
  if (demo.time.size() < 2 || demo.time.size() != static_cast<std::size_t>(demo.rows()))
    throw std::invalid_argument(
        "no clock: time parameters are in seconds, so the samples need timestamps (a time "
        "column, bag stamps, or a rate)");
  std::vector<double> steps(demo.time.size() - 1);
  for (std::size_t i = 1; i < demo.time.size(); ++i) steps[i - 1] = demo.time[i] - demo.time[i - 1];
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double step = steps[steps.size() / 2];
  if (!(step > 0) || !std::isfinite(step))
    throw std::invalid_argument("the clock does not increase (median time step " +
                                std::to_string(step) + " s)");
  return 1.0 / step;
}

namespace {

// Every demonstration is a well-formed matrix with at least 2 samples.
void checkDemoShapes(const std::vector<FeatureMatrix>& demos) {
  for (std::size_t d = 0; d < demos.size(); ++d) {
    try {
      demos[d].validateShape();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demoLabel(d) + ": " + e.what());
    }
    if (demos[d].rows() < 2) {
      throw std::invalid_argument(demoLabel(d) + " has " + std::to_string(demos[d].rows()) +
                                  " samples; at least 2 are needed");
    }
  }
}

// The named roles exist; without named state features, every feature that is not a sensor is one.
void assignFeatureRoles(const FeatureMatrix& first, const std::vector<std::string>& sensor_features,
                        const std::vector<std::string>& state_features,
                        SegmentationPipelineResult* result) {
  for (const std::string& s : sensor_features) {
    if (first.indexOf(s) < 0) {
      throw std::invalid_argument("sensor feature '" + s + "' is not in the demonstrations");
    }
  }
  if (state_features.empty()) {
    for (const std::string& name : first.names) {
      if (std::find(sensor_features.begin(), sensor_features.end(), name) == sensor_features.end())
        result->state_features.push_back(name);
    }
  } else {
    for (const std::string& s : state_features) {
      if (first.indexOf(s) < 0) {
        throw std::invalid_argument("state feature '" + s + "' is not in the demonstrations");
      }
    }
    result->state_features = state_features;
  }
  result->sensor_features = sensor_features;
  if (result->state_features.empty()) {
    throw std::invalid_argument("no state feature to segment (every feature is a sensor)");
  }
}

// Constant state features carry no information: they are dropped with a warning.
std::vector<std::string> informativeStateFeatures(const std::vector<FeatureMatrix>& demos,
                                                  SegmentationPipelineResult* result) {
  std::vector<std::string> informative;
  for (const std::string& name : result->state_features) {
    bool constant_everywhere = true;
    for (const FeatureMatrix& demo : demos) {
      constant_everywhere = constant_everywhere && isConstant(demo, demo.require(name));
    }
    if (constant_everywhere) {
      result->warnings.push_back("state feature '" + name +
                                 "' is constant in every demonstration and is ignored");
    } else {
      informative.push_back(name);
    }
  }
  if (informative.empty()) {
    throw std::invalid_argument("every state feature is constant: nothing to segment");
  }
  return informative;
}

// II-B feature relevance picks and weighs the features; it needs >= 2 demonstrations, so a single
// one uses every informative feature with equal weights.
void selectWeightedFeatures(const std::vector<FeatureMatrix>& demos,
                            const std::vector<std::string>& informative,
                            const SegmentationPipelineConfig& config,
                            SegmentationPipelineResult* result) {
  if (demos.size() >= 2) {
    FeatureRelevanceConfig relevance_config = config.relevance;
    relevance_config.threads = config.threads;
    result->relevance = computeFeatureRelevance(demos, informative, relevance_config);
    result->relevance_computed = true;
    for (const std::string& w : result->relevance.warnings) result->warnings.push_back(w);
    result->selected_features = result->relevance.selected;
    for (double score : result->relevance.selectedScores()) {
      // Weights must be positive; a non-positive best score (warned above) keeps weight 1.
      result->feature_weights.push_back(score > 0 ? score : 1.0);
    }
    if (result->selected_features.empty()) {
      throw std::invalid_argument("feature relevance selected no feature");
    }
  } else {
    result->warnings.push_back(
        "a single demonstration: feature relevance needs at least 2, so every non-constant "
        "state feature is used with equal weights");
    result->selected_features = informative;
    result->feature_weights.assign(informative.size(), 1.0);
  }
}

}  // namespace

PreparedSegmentation prepareSegmentation(const std::vector<FeatureMatrix>& demos,
                                         const std::vector<std::string>& sensor_features,
                                         const SegmentationPipelineConfig& config,
                                         const std::vector<std::string>& state_features) {
  if (demos.empty()) throw std::invalid_argument("no demonstrations to segment");
  PreparedSegmentation prepared;
  SegmentationPipelineResult& result = prepared.base;

  // ---- input checks: shape, same features, roles, finite samples, lengths
  checkDemoShapes(demos);
  checkSameFeatures(demos);
  assignFeatureRoles(demos[0], sensor_features, state_features, &result);
  std::vector<std::string> used = result.state_features;
  used.insert(used.end(), sensor_features.begin(), sensor_features.end());
  for (std::size_t d = 0; d < demos.size(); ++d) checkFinite(demos[d].select(used), demoLabel(d));

  demoSettings(demos, config);  // checks every demo's clock and length

  const std::vector<std::string> informative = informativeStateFeatures(demos, &result);

  const auto relevance_start = std::chrono::steady_clock::now();
  selectWeightedFeatures(demos, informative, config, &result);
  result.relevance_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - relevance_start).count();
  return prepared;
}

SegmentationPipelineResult segmentPrepared(const PreparedSegmentation& prepared,
                                           const std::vector<FeatureMatrix>& demos,
                                           const SegmentationPipelineConfig& config) {
  return makeSegmentationMethod(toString(config.procedure))->segment(prepared, demos, config);
}

void addSensorWarnings(const std::vector<FeatureMatrix>& demos, bool validated,
                       SegmentationPipelineResult* result) {
  for (std::size_t d = 0; d < demos.size() && validated; ++d) {
    for (const std::string& sensor : result->sensor_features) {
      if (isConstant(demos[d], demos[d].require(sensor)))
        result->warnings.push_back(demoLabel(d) + ": sensor '" + sensor +
                                   "' is constant (dead or disconnected?): no event from it");
    }
    if (result->demos[d].events.empty())
      result->warnings.push_back(demoLabel(d) + ": no sensory event detected");
  }
}

SegmentationPipelineResult runSegmentationPipeline(const std::vector<FeatureMatrix>& demos,
                                                   const std::vector<std::string>& sensor_features,
                                                   const SegmentationPipelineConfig& config,
                                                   const std::vector<std::string>& state_features) {
  return segmentPrepared(prepareSegmentation(demos, sensor_features, config, state_features), demos,
                         config);
}

}  // namespace lfd
