#include "lfd_segmentation/segmentation_json.hpp"

#include <algorithm>
#include <cmath>

namespace lfd_segmentation {

namespace {

using nlohmann::json;

json vectorJson(const Eigen::VectorXd& v) {
  json out = json::array();
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    out.push_back(std::isfinite(v[k]) ? json(v[k]) : json(nullptr));
  }
  return out;
}

// Decimals of a feature's rounding step (10^-decimals <= kFeatureResolution x its range, or its
// magnitude when constant); kKeepDigits when there is nothing to scale by.
constexpr int kKeepDigits = 99;
int featureDecimals(const Eigen::VectorXd& values) {
  if (values.size() == 0 || !values.allFinite()) return kKeepDigits;
  const double lo = values.minCoeff(), hi = values.maxCoeff();
  const double span = hi > lo ? hi - lo : std::max(std::abs(lo), std::abs(hi));
  if (!(span > 0)) return kKeepDigits;
  return static_cast<int>(-std::floor(std::log10(span * kFeatureResolution)));
}

// x as the double nearest to a multiple of 10^-decimals, which the JSON writer (shortest round
// trip) prints with no more digits than the step: n / 10^k and n * 10^k are correctly rounded
// operations on exact integers (|n| < 2^53, 10^k exact for k <= 22).
double roundDecimals(double x, int decimals) {
  if (!std::isfinite(x) || std::abs(decimals) > 22) return x;
  double scale = 1;
  for (int k = 0; k < std::abs(decimals); ++k) scale *= 10;
  const double n = std::round(decimals >= 0 ? x * scale : x / scale);
  if (std::abs(n) >= 9007199254740992.0) return x;
  return (decimals >= 0 ? n / scale : n * scale) + 0.0;  // + 0.0: -0 prints as 0
}

json roundedJson(const Eigen::VectorXd& v) {
  const int decimals = featureDecimals(v);
  json out = json::array();
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    out.push_back(std::isfinite(v[k]) ? json(roundDecimals(v[k], decimals)) : json(nullptr));
  }
  return out;
}

const char* roleOf(const std::string& name, const std::vector<std::string>& states,
                   const std::vector<std::string>& sensors) {
  auto in = [&](const std::vector<std::string>& list) {
    return std::find(list.begin(), list.end(), name) != list.end();
  };
  return in(states) ? "state" : in(sensors) ? "sensor" : "context";
}

// Feature names, file names and errors come from the user's files and may hold any bytes: invalid
// UTF-8 is written as U+FFFD instead of throwing (nlohmann's type_error 316 aborted the CLI).
std::string dumpText(const json& j) {
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

bool isFlat(const json& j) {
  return !j.is_structured() || j.empty() ||
         (j.is_array() &&
          std::none_of(j.begin(), j.end(), [](const json& e) { return e.is_structured(); }));
}

void dumpIndented(const json& j, int depth, std::string& out) {
  if (isFlat(j)) {
    out += dumpText(j);
    return;
  }
  const std::string pad(static_cast<std::size_t>(depth) + 1, ' ');
  out += j.is_object() ? '{' : '[';
  for (auto it = j.begin(); it != j.end(); ++it) {
    out += (it == j.begin() ? "\n" : ",\n") + pad;
    if (j.is_object()) out += dumpText(json(it.key())) + ": ";
    dumpIndented(*it, depth + 1, out);
  }
  out += "\n" + std::string(static_cast<std::size_t>(depth), ' ') + (j.is_object() ? '}' : ']');
}

json matrixJson(const Eigen::MatrixXd& m) {
  json out = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) out.push_back(vectorJson(m.row(r).transpose()));
  return out;
}

json timesJson(const std::vector<std::size_t>& indices, const lfd::FeatureMatrix& demo) {
  json out = json::array();
  for (std::size_t i : indices) out.push_back(demo.timeAt(static_cast<Eigen::Index>(i)));
  return out;
}

// Closed row intervals with their times (the end clipped to the demo).
json intervalsJson(const std::vector<lfd::Interval>& intervals, const lfd::FeatureMatrix& demo) {
  json out = json::array();
  for (const lfd::Interval& z : intervals) {
    const std::size_t end = std::min<std::size_t>(z.end, static_cast<std::size_t>(demo.rows()) - 1);
    out.push_back({{"begin", z.begin},
                   {"end", z.end},
                   {"begin_time", demo.timeAt(static_cast<Eigen::Index>(z.begin))},
                   {"end_time", demo.timeAt(static_cast<Eigen::Index>(end))}});
  }
  return out;
}

json claspJson(const lfd::MultivariateSegmentation& s, const lfd::FeatureMatrix& demo,
               const std::vector<std::string>& features, const JsonOptions& options) {
  json out;
  out["clasp_changepoints"] = s.changepoints;
  out["clasp_changepoint_times"] = timesJson(s.changepoints, demo);
  json candidates = json::array();
  for (const lfd::SplitCandidate& c : s.candidates) {
    candidates.push_back(
        {{"index", c.index},
         {"time", demo.timeAt(static_cast<Eigen::Index>(c.index))},
         {"range", {c.range_begin, c.range_end}},
         {"score", std::isfinite(c.score) ? json(c.score) : json(nullptr)},
         {"log10_p_value", std::isfinite(c.log10_p_value) ? json(c.log10_p_value) : json(nullptr)},
         {"accepted_by_clasp", c.accepted},
         {"anchored_to_event", c.anchored},
         {"profile_argmax", c.profile_argmax}});
  }
  out["candidates"] = candidates;
  json windows = json::object();
  for (std::size_t f = 0; f < features.size() && f < s.window_sizes.size(); ++f) {
    windows[features[f]] = s.window_sizes[f];
  }
  out["window_sizes"] = windows;
  out["min_segment_length"] = s.min_segment_length;
  if (options.profiles) {
    out["profile"] = vectorJson(s.first_profile);
    out["profile_penalized"] = vectorJson(s.first_profile_penalized);
  }
  if (options.feature_profiles) {
    json profiles = json::object();
    for (std::size_t f = 0; f < features.size() && f < s.first_feature_profiles.size(); ++f) {
      profiles[features[f]] = vectorJson(s.first_feature_profiles[f]);
    }
    out["feature_profiles"] = profiles;
  }
  return out;
}

}  // namespace

json toJson(const lfd::SegmentationPipelineResult& r, const std::vector<lfd::FeatureMatrix>& demos,
            const std::vector<std::string>& sources, const JsonOptions& options) {
  json out;
  out["warnings"] = r.warnings;
  out["state_features"] = r.state_features;
  out["sensor_features"] = r.sensor_features;
  out["selected_features"] = r.selected_features;
  out["feature_weights"] = r.feature_weights;
  out["relevance_computed"] = r.relevance_computed;
  out["stage_seconds"] = {{"relevance", r.relevance_seconds},
                          {"segmentation", r.segmentation_seconds}};
  if (r.relevance_computed) {
    json features = json::array();
    for (const lfd::FeatureRelevance& f : r.relevance.features) {
      features.push_back({{"name", f.name},
                          {"mean_correlation", f.mean_correlation},
                          {"mean_distance", f.mean_distance},
                          {"normalized_distance", f.normalized_distance},
                          {"score", f.score},
                          {"constant", f.constant},
                          {"selected", f.selected},
                          {"selected_correlation_only", f.selected_correlation_only},
                          {"correlation", matrixJson(f.correlation)},
                          {"distance", matrixJson(f.distance)}});
    }
    out["relevance"] = {{"features", features},
                        {"selected", r.relevance.selected},
                        {"selected_correlation_only", r.relevance.selected_correlation_only}};
  }
  json demo_list = json::array();
  for (std::size_t d = 0; d < r.demos.size(); ++d) {
    const lfd::DemoSegmentationResult& s = r.demos[d];
    json demo = claspJson(s.clasp, demos[d], r.selected_features, options);
    demo["source"] = d < sources.size() ? sources[d] : "";
    demo["num_samples"] = s.num_samples;
    demo["changepoints"] = s.changepoints;
    demo["changepoint_times"] = s.changepoint_times;
    demo["changepoint_evidence"] = s.changepoint_evidence;
    demo["rejected"] = s.rejected;
    demo["rejected_times"] = s.rejected_times;
    demo["pruned"] = s.pruned;
    demo["pruned_times"] = s.pruned_times;
    demo["added"] = s.added;
    demo["added_times"] = s.added_times;
    demo["events"] = s.events;
    demo["event_times"] = timesJson(s.events, demos[d]);
    std::vector<std::size_t> rest_edges;
    for (const lfd::SensoryEvent& e : s.event_details)
      if (e.rest_edge) rest_edges.push_back(e.index);
    demo["rest_edge_event_times"] = timesJson(rest_edges, demos[d]);
    demo["sample_rate"] = s.sample_rate;
    demo["zones"] = intervalsJson(s.zones, demos[d]);
    demo["pauses"] = intervalsJson(s.pauses, demos[d]);
    demo_list.push_back(demo);
  }
  out["demos"] = demo_list;
  return out;
}

json toJson(const lfd::MultivariateSegmentation& s, const lfd::FeatureMatrix& demo,
            const std::string& source, const JsonOptions& options) {
  json out;
  out["selected_features"] = demo.names;
  json d = claspJson(s, demo, demo.names, options);
  d["source"] = source;
  d["num_samples"] = demo.rows();
  d["changepoints"] = s.changepoints;
  d["changepoint_times"] = timesJson(s.changepoints, demo);
  out["demos"] = json::array({d});
  out["warnings"] = json::array();
  return out;
}

json featureMatricesJson(const std::vector<lfd::FeatureMatrix>& demos,
                         const std::vector<std::string>& states,
                         const std::vector<std::string>& sensors) {
  json out = json::array();
  for (const lfd::FeatureMatrix& demo : demos) {
    json features = json::array();
    for (Eigen::Index c = 0; c < demo.cols(); ++c) {
      const std::string& name = demo.names.at(static_cast<std::size_t>(c));
      features.push_back({{"name", name},
                          {"role", roleOf(name, states, sensors)},
                          {"values", roundedJson(demo.data.col(c))}});
    }
    json time = json::array();  // timeAt: a series without a clock is on its row index
    for (Eigen::Index r = 0; r < demo.rows(); ++r) time.push_back(demo.timeAt(r));
    out.push_back({{"time", time}, {"features", features}});
  }
  return out;
}

lfd::OutputKind segmentationResultOutput() {
  const lfd::OutputKind success_mode =
      lfd::jsonOutput("segmentation result", kSegmentationResultFormat, {"success", "mode"});
  const lfd::OutputKind success_error =
      lfd::jsonOutput("segmentation result", kSegmentationResultFormat, {"success", "error"});
  return {"segmentation result", [=](const lfd::InputFile& file) {
            return success_mode.written_by_lfd(file) || success_error.written_by_lfd(file);
          }};
}

std::string dumpJson(const json& j) {
  std::string out;
  dumpIndented(j, 0, out);
  return out;
}

}  // namespace lfd_segmentation
