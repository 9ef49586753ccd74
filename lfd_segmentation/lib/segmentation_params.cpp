#include "lfd_segmentation/segmentation_params.hpp"

#include "lfd_core/io/safe_paths.hpp"
#include "lfd_core/io/user_text.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace lfd_segmentation {

namespace {

template <typename T>
T get(const YAML::Node& node, const std::string& key, T fallback) {
  if (!node || !node[key]) return fallback;
  try {
    return node[key].as<T>();
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument("segmentation parameter '" + key +
                                "' has a bad value: " + e.what());
  }
}

double nonNegative(double value, const std::string& key) {
  if (!(value >= 0) || !std::isfinite(value)) {
    throw std::invalid_argument("segmentation parameter " + lfd::quoted(key) +
                                " must be >= 0, got " + std::to_string(value));
  }
  return value;
}

double positive(double value, const std::string& key) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw std::invalid_argument("segmentation parameter " + lfd::quoted(key) +
                                " must be > 0 and finite");
  }
  return value;
}

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string seconds(double s) {
  return number(s) + " s";
}

TopicConfig parseTopic(const YAML::Node& node, std::size_t index) {
  const std::string where = "topics[" + std::to_string(index) + "]";
  if (!node.IsMap()) throw std::invalid_argument(where + " must be a map");
  TopicConfig topic;
  topic.topic = get<std::string>(node, "topic", "");
  if (topic.topic.empty()) throw std::invalid_argument(where + " has no 'topic'");
  if (topic.topic == kGroundTruthTopic) {
    throw std::invalid_argument(where + ": " + kGroundTruthTopic +
                                " is ground truth for evaluation and must not be segmented");
  }
  const std::string role = get<std::string>(node, "role", "state");
  if (role == "state") {
    topic.role = FeatureRole::kState;
  } else if (role == "sensor") {
    topic.role = FeatureRole::kSensor;
  } else if (role == "context") {
    topic.role = FeatureRole::kContext;
  } else {
    throw std::invalid_argument(where + ": role must be 'state', 'sensor' or 'context', got " +
                                lfd::quoted(role));
  }
  topic.monitor = get<bool>(node, "monitor", topic.role != FeatureRole::kState);
  const std::string interpolation = get<std::string>(node, "interpolation", "linear");
  if (interpolation == "linear") {
    topic.interpolation = lfd::Interpolation::kLinear;
  } else if (interpolation == "zoh" || interpolation == "zero_order_hold") {
    topic.interpolation = lfd::Interpolation::kZeroOrderHold;
  } else {
    throw std::invalid_argument(where + ": interpolation must be 'linear' or 'zoh'");
  }
  topic.fields = get<std::vector<std::string>>(node, "fields", {});
  if (topic.fields.empty())
    throw std::invalid_argument(where + " (" + topic.topic + ") has no fields");
  return topic;
}

double fraction(double value, const std::string& key) {
  if (!(value >= 0 && value <= 1))
    throw std::invalid_argument("segmentation parameter '" + key + "' must be in [0, 1]");
  return value;
}

// The numbers of one YAML section, each read over its default, checked, and named in an error by
// its path ("joint/pauses/rest_fraction").
class Section {
 public:
  Section(const YAML::Node& node, std::string path) : node_(node), path_(std::move(path)) {}
  Section child(const char* key) const {
    return Section(node_ ? node_[key] : YAML::Node(), path_ + key + "/");
  }
  void readFraction(const char* key, double& value) const {
    value = fraction(get<double>(node_, key, value), path_ + key);
  }
  void readNonNegative(const char* key, double& value) const {
    value = nonNegative(get<double>(node_, key, value), path_ + key);
  }
  void readPositive(const char* key, double& value) const {
    value = positive(get<double>(node_, key, value), path_ + key);
  }

 private:
  YAML::Node node_;
  std::string path_;
};

// joint: the joint segmentation's evidence weights, pauses, alignment and agreement.
void parseJoint(const YAML::Node& node, lfd::JointSegmentationConfig* joint) {
  const Section section(node, "joint/");
  const Section w = section.child("weights");
  auto& weights = joint->weights;
  w.readFraction("contact", weights.contact);
  w.readFraction("sensor_level", weights.sensor_level);
  w.readFraction("motion_onset", weights.motion_onset);
  w.readFraction("motion_stop", weights.motion_stop);
  w.readFraction("clasp", weights.clasp);
  w.readFraction("rhythm", weights.rhythm);
  const Section pause = section.child("pauses");
  auto& pc = joint->pauses;
  pause.readNonNegative("smoothing_seconds", pc.smoothing);
  pause.readFraction("rest_fraction", pc.rest_fraction);
  pause.readNonNegative("min_pause_seconds", pc.min_pause);
  pause.readPositive("pause_scale_seconds", pc.pause_scale);
  pause.readPositive("motion_window_seconds", pc.motion_window);
  section.readPositive("grid_step_seconds", joint->grid_step);
  section.readPositive("alignment_band", joint->alignment_band);
  section.readPositive("spread_seconds", joint->spread);
  section.readPositive("agreement_spread_seconds", joint->agreement_spread);
  section.readFraction("min_support", joint->min_support);
  section.readFraction("short_phase_support", joint->short_phase_support);
  section.readPositive("match_window_seconds", joint->match_window);
  section.readNonNegative("event_merge_gap_seconds", joint->event_merge_gap);
  section.readNonNegative("ramp_fold_seconds", joint->ramp_fold);
  section.readNonNegative("stale_reading_seconds", joint->stale_reading);
  section.readPositive("motion_match_window_seconds", joint->motion_match_window);
  section.readPositive("motion_match_step_seconds", joint->motion_match_step);
  section.readPositive("rhythm_min_range_sigmas", joint->rhythm_min_range_sigmas);
  section.readFraction("min_piece_weight", joint->min_piece_weight);
  section.readNonNegative("colocation_seconds", joint->colocation);
  joint->max_speed_correlation =
      get<double>(node, "max_speed_correlation", joint->max_speed_correlation);
  section.readFraction("extra_event_weight", joint->extra_event_weight);
}

// The ClaSP profile and its significance test (segmentation.yaml `clasp`, and the combination,
// window and changepoint keys at the top level).
void parseClasp(const YAML::Node& root, SegmentationParams& p) {
  auto& seg = p.pipeline.segmentation;
  seg.combination = lfd::parseProfileCombination(
      get<std::string>(root, "combination", lfd::toString(seg.combination)));
  p.min_segment_seconds =
      nonNegative(get<double>(root, "min_segment_seconds", 0.0), "min_segment_seconds");
  p.window_seconds = nonNegative(get<double>(root, "window_seconds", 0.0), "window_seconds");
  seg.num_changepoints = get<int>(root, "num_changepoints", seg.num_changepoints);
  seg.max_changepoints = get<std::size_t>(root, "max_changepoints", seg.max_changepoints);
  seg.kaiser_beta = nonNegative(get<double>(root, "kaiser_beta", seg.kaiser_beta), "kaiser_beta");
  seg.zone_p_value_threshold =
      nonNegative(get<double>(root, "zone_p_value_threshold", seg.zone_p_value_threshold),
                  "zone_p_value_threshold");
  seg.rest_edge_p_value_threshold =
      nonNegative(get<double>(root, "rest_edge_p_value_threshold", seg.rest_edge_p_value_threshold),
                  "rest_edge_p_value_threshold");
  const YAML::Node clasp = root["clasp"];
  auto& cc = seg.clasp;
  cc.window_selection = lfd::parseWindowSelection(
      get<std::string>(clasp, "window_selection", lfd::toString(cc.window_selection)));
  p.time.min_window = nonNegative(get<double>(clasp, "min_window_seconds", p.time.min_window),
                                  "clasp/min_window_seconds");
  cc.k = get<std::size_t>(clasp, "k", cc.k);
  cc.distance =
      lfd::parseClaspDistance(get<std::string>(clasp, "distance", lfd::toString(cc.distance)));
  cc.score = lfd::parseClaspScore(get<std::string>(clasp, "score", lfd::toString(cc.score)));
  cc.p_value_threshold = get<double>(clasp, "p_value_threshold", cc.p_value_threshold);
  seg.significance_per_sample =
      nonNegative(get<double>(clasp, "significance_per_sample", seg.significance_per_sample),
                  "clasp/significance_per_sample");
  cc.tie_jitter = nonNegative(get<double>(clasp, "tie_jitter", cc.tie_jitter), "clasp/tie_jitter");

  if (clasp && clasp["min_window"])
    throw std::invalid_argument(
        "segmentation parameter 'clasp/min_window' counts samples; give clasp/min_window_seconds");
}

// The procedure that combines candidates, zones and consensus (top-level keys).
void parseProcedure(const YAML::Node& root, SegmentationParams& p) {
  p.pipeline.validate_with_sensors =
      get<bool>(root, "validate_with_sensors", p.pipeline.validate_with_sensors);
  p.pipeline.procedure = lfd::parseSegmentationProcedure(
      get<std::string>(root, "procedure", lfd::toString(p.pipeline.procedure)));
  if (root["search_in_zones"])
    throw std::invalid_argument(
        "segmentation parameter 'search_in_zones' is now 'procedure' (zone_search or paper)");
  p.pipeline.paper_candidates =
      get<std::size_t>(root, "paper_candidates", p.pipeline.paper_candidates);
  if (p.pipeline.paper_candidates < 1 ||
      p.pipeline.paper_candidates > p.pipeline.segmentation.max_changepoints)
    throw std::invalid_argument("segmentation parameter 'paper_candidates' must be in [1, " +
                                std::to_string(p.pipeline.segmentation.max_changepoints) +
                                "] (max_changepoints)");
  p.pipeline.anchor_to_events = get<bool>(root, "anchor_to_events", p.pipeline.anchor_to_events);
  p.pipeline.consensus_count = get<bool>(root, "consensus_count", p.pipeline.consensus_count);
  p.pipeline.consensus_fill_p_value =
      get<double>(root, "consensus_fill_p_value", p.pipeline.consensus_fill_p_value);
  if (!(p.pipeline.consensus_fill_p_value >= 0.0 && p.pipeline.consensus_fill_p_value < 1.0))
    throw std::invalid_argument(
        "segmentation parameter 'consensus_fill_p_value' must be in [0, 1)");
  p.pipeline.threads = get<int>(root, "threads", p.pipeline.threads);
}

// Sensory events and their confidence zones (segmentation.yaml `events`).
void parseEvents(const YAML::Node& root, SegmentationParams& p) {
  const YAML::Node events = root["events"];
  auto& ev = p.pipeline.events;
  ev.threshold =
      lfd::parseEventThreshold(get<std::string>(events, "threshold", lfd::toString(ev.threshold)));
  ev.threshold_ratio = get<double>(events, "threshold_ratio", ev.threshold_ratio);
  ev.relative_floor = get<double>(events, "relative_floor", ev.relative_floor);
  ev.noise_floor_sigmas = get<double>(events, "noise_floor_sigmas", ev.noise_floor_sigmas);
  ev.noise_floor_excursions =
      get<double>(events, "noise_floor_excursions", ev.noise_floor_excursions);
  ev.hysteresis = get<double>(events, "hysteresis", ev.hysteresis);
  ev.zones_from_rest_edges = get<bool>(events, "zones_from_rest_edges", ev.zones_from_rest_edges);
  ev.rest_edge_sigmas = nonNegative(get<double>(events, "rest_edge_sigmas", ev.rest_edge_sigmas),
                                    "events/rest_edge_sigmas");
  ev.placement =
      lfd::parseEventPlacement(get<std::string>(events, "placement", lfd::toString(ev.placement)));
  if (events && events["place_on_change"])
    throw std::invalid_argument(
        "segmentation parameter 'events/place_on_change' is now 'events/placement' (threshold, "
        "shift or fit)");
  auto& t = p.time;
  const Section event_times(events, "events/");
  event_times.readNonNegative("median_seconds", t.event_median);
  event_times.readNonNegative("difference_lag_seconds", t.event_difference_lag);
  event_times.readNonNegative("merge_gap_seconds", t.event_merge_gap);
  event_times.readNonNegative("min_active_seconds", t.event_min_active);
  event_times.readNonNegative("noise_block_seconds", t.event_noise_block);
  // Sample counts would silently mean something else at another rate: refuse them.
  for (const char* key : {"median_window", "merge_gap", "difference_lag", "min_active_samples"})
    if (events && events[key])
      throw std::invalid_argument(std::string("segmentation parameter 'events/") + key +
                                  "' counts samples; give it in seconds (events/*_seconds)");
}

// Request limits (segmentation.yaml `limits`) and the folders a request may name.
void parseLimits(const YAML::Node& root, SegmentationParams& p) {
  const YAML::Node limits = root["limits"];
  auto& lim = p.limits;
  lim.max_bags = get<std::size_t>(limits, "max_bags", lim.max_bags);
  lim.max_bag_files = get<std::size_t>(limits, "max_bag_files", lim.max_bag_files);
  lim.max_total_bytes = get<std::uint64_t>(limits, "max_total_bytes", lim.max_total_bytes);
  lim.max_demo_seconds = positive(get<double>(limits, "max_demo_seconds", lim.max_demo_seconds),
                                  "limits/max_demo_seconds");
  lim.max_samples_per_demo =
      get<std::size_t>(limits, "max_samples_per_demo", lim.max_samples_per_demo);
  lim.max_total_samples = get<std::size_t>(limits, "max_total_samples", lim.max_total_samples);
  lim.max_csv_rows = get<std::size_t>(limits, "max_csv_rows", lim.max_csv_rows);
  lim.max_abs_value =
      positive(get<double>(limits, "max_abs_value", lim.max_abs_value), "limits/max_abs_value");
  lim.max_features = get<std::size_t>(limits, "max_features", lim.max_features);
  lim.max_request_string_bytes =
      get<std::size_t>(limits, "max_request_string_bytes", lim.max_request_string_bytes);
  p.paths.allowed_roots = get<std::vector<std::string>>(root, "allowed_roots", {});
}

void parseTopics(const YAML::Node& root, SegmentationParams& p) {
  const YAML::Node topics = root["topics"];
  if (topics) {
    if (!topics.IsSequence())
      throw std::invalid_argument("segmentation parameter 'topics' must be a list");
    for (std::size_t k = 0; k < topics.size(); ++k) p.topics.push_back(parseTopic(topics[k], k));
  }
}

}  // namespace

lfd::SegmentationPipelineConfig SegmentationParams::pipelineConfig() const {
  lfd::SegmentationPipelineConfig config = pipeline;
  config.seconds = time;
  config.seconds->min_segment = min_segment_seconds;
  config.seconds->window = window_seconds;
  lfd::SegmentationPipelineConfig nominal = lfd::inSamples(config, rate);
  nominal.seconds = config.seconds;
  return nominal;
}

SegmentationParams paramsFromYaml(const YAML::Node& root) {
  SegmentationParams p;
  p.rate = get<double>(root, "rate", p.rate);
  if (!(p.rate > 0) || !std::isfinite(p.rate)) {
    throw std::invalid_argument("segmentation parameter 'rate' must be > 0");
  }
  auto& relevance = p.pipeline.relevance;
  relevance.threshold = get<double>(root, "threshold", relevance.threshold);
  if (!(relevance.threshold > 0 && relevance.threshold <= 1)) {
    throw std::invalid_argument("segmentation parameter 'threshold' must be in (0,1]");
  }
  relevance.band_fraction = get<double>(root, "dtw_band_fraction", relevance.band_fraction);
  relevance.normalize_per_demo =
      get<bool>(root, "normalize_per_demo", relevance.normalize_per_demo);

  parseClasp(root, p);
  parseProcedure(root, p);
  parseJoint(root["joint"], &p.pipeline.joint);
  parseEvents(root, p);
  parseLimits(root, p);
  parseTopics(root, p);
  return p;
}

SegmentationParams loadParamsFile(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(lfd::openInputFile(path).readPath());  // no FIFO swapped in
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("cannot read segmentation parameters: " + std::string(e.what()));
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument("cannot read segmentation parameters " + lfd::quoted(path) + ": " +
                                e.what());
  }
  return paramsFromYaml(root);
}

void checkSecondsOverride(double value, const std::string& key, const RequestLimits& limits) {
  if (value == 0) return;  // 0 = keep the parameter
  if (!std::isfinite(value) || value > limits.max_demo_seconds) {
    throw std::invalid_argument(key + " = " + seconds(value) +
                                " is not a duration a demo can have (limit " +
                                seconds(limits.max_demo_seconds) + ", limits/max_demo_seconds)");
  }
}

void checkDemosFit(const SegmentationParams& params, const std::vector<lfd::FeatureMatrix>& demos,
                   const std::vector<std::string>& sources) {
  const RequestLimits& lim = params.limits;
  std::size_t total = 0;
  for (std::size_t d = 0; d < demos.size(); ++d) {
    const lfd::FeatureMatrix& m = demos[d];
    const std::string& source = d < sources.size() ? sources[d] : "demo " + std::to_string(d);
    const std::size_t rows = static_cast<std::size_t>(m.rows());
    if (rows > lim.max_samples_per_demo) {
      throw std::invalid_argument(lfd::quoted(source) + " has " + std::to_string(rows) +
                                  " samples on its clock, over the limit of " +
                                  std::to_string(lim.max_samples_per_demo) +
                                  " (limits/max_samples_per_demo): put it on a slower clock "
                                  "(bags: rate; the segment CLI's CSV: --resample HZ)");
    }
    total += rows;
    if (rows < 2) continue;
    const double length = m.timeAt(m.rows() - 1) - m.timeAt(0);
    if (params.window_seconds > 0 && params.window_seconds >= length) {
      throw std::invalid_argument(
          "window_seconds = " + seconds(params.window_seconds) + " is not shorter than '" + source +
          "' (" + seconds(length) +
          "): the window covers the whole demo, no changepoint can be found");
    }
  }
  if (total > lim.max_total_samples) {
    throw std::invalid_argument("the request's demos hold " + std::to_string(total) +
                                " samples after resampling, over the limit of " +
                                std::to_string(lim.max_total_samples) +
                                " (limits/max_total_samples)");
  }
}

void checkStreams(const std::vector<lfd::Stream>& streams, const std::string& source,
                  const RequestLimits& limits) {
  for (const lfd::Stream& s : streams) {
    if (!s.time.empty()) {
      const auto [first, last] = std::minmax_element(s.time.begin(), s.time.end());
      if (*last - *first > limits.max_demo_seconds) {
        throw std::invalid_argument(lfd::quoted(source) + ": " + s.name + " has stamps " +
                                    seconds(*last - *first) + " apart (first " + seconds(*first) +
                                    ", last " + seconds(*last) + "), over the limit of " +
                                    seconds(limits.max_demo_seconds) +
                                    " (limits/max_demo_seconds)");
      }
    }
    for (std::size_t k = 0; k < s.values.size(); ++k) {
      if (std::abs(s.values[k]) > limits.max_abs_value) {
        throw std::invalid_argument(
            lfd::quoted(source) + ": " + s.name + " = " + number(s.values[k]) +
            " at t = " + seconds(k < s.time.size() ? s.time[k] : 0.0) + " is beyond +-" +
            number(limits.max_abs_value) + " (limits/max_abs_value): distances would overflow");
      }
    }
  }
}

}  // namespace lfd_segmentation
