#include "lfd_core/segmentation_pipeline.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace lfd {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out;
}

std::string demo_context(std::size_t d) {
  return "demonstration " + std::to_string(d);
}

// Every demonstration must carry the same feature names (in any order).
void check_same_features(const std::vector<FeatureMatrix>& demos) {
  const std::set<std::string> reference(demos[0].names.begin(), demos[0].names.end());
  if (reference.size() != demos[0].names.size()) {
    throw std::invalid_argument(demo_context(0) + " has duplicate feature names");
  }
  for (std::size_t d = 1; d < demos.size(); ++d) {
    const std::set<std::string> names(demos[d].names.begin(), demos[d].names.end());
    if (names.size() != demos[d].names.size()) {
      throw std::invalid_argument(demo_context(d) + " has duplicate feature names");
    }
    if (names == reference) continue;
    std::vector<std::string> missing, extra;
    std::set_difference(reference.begin(), reference.end(), names.begin(), names.end(),
                        std::back_inserter(missing));
    std::set_difference(names.begin(), names.end(), reference.begin(), reference.end(),
                        std::back_inserter(extra));
    std::string msg = "features differ between demonstrations: " + demo_context(d);
    if (!missing.empty()) msg += " lacks " + join(missing);
    if (!extra.empty()) msg += (missing.empty() ? " has extra " : " and has extra ") + join(extra);
    throw std::invalid_argument(msg + " (compared with " + demo_context(0) + ")");
  }
}

bool is_constant(const FeatureMatrix& demo, int col) {
  const double lo = demo.data.col(col).minCoeff(), hi = demo.data.col(col).maxCoeff();
  return !(hi - lo > 1e-12 * (1.0 + std::max(std::abs(hi), std::abs(lo))));
}

// The channels of one sensor share their name up to the last '/' (a topic's array or vector:
// /touch/values/0 and /touch/values/1); names without '/' (CSV columns) are one sensor.
std::vector<std::size_t> sensor_groups(const std::vector<std::string>& names) {
  std::map<std::string, std::size_t> ids;
  std::vector<std::size_t> groups;
  for (const std::string& name : names) {
    const std::size_t slash = name.rfind('/');
    const std::string sensor = slash == std::string::npos ? "" : name.substr(0, slash);
    groups.push_back(ids.emplace(sensor, ids.size()).first->second);
  }
  return groups;
}

// Runs job(d) for every demonstration on up to `threads` threads; rethrows the first failure (by
// demonstration index) with the demonstration named.
template <typename Job>
void for_each_demo(std::size_t count, int threads, Job job) {
  std::vector<std::exception_ptr> errors(count);
  std::atomic<std::size_t> next{0};
  auto worker = [&]() {
    for (std::size_t d = next++; d < count; d = next++) {
      try {
        job(d);
      } catch (...) {
        errors[d] = std::current_exception();
      }
    }
  };
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = static_cast<int>(std::min<std::size_t>(threads, count));
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  for (std::size_t d = 0; d < count; ++d) {
    if (!errors[d]) continue;
    try {
      std::rethrow_exception(errors[d]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demo_context(d) + ": " + e.what());
    } catch (const std::exception& e) {
      throw std::runtime_error(demo_context(d) + ": " + e.what());
    }
  }
}

// The sample-count settings of one demonstration: the config's own counts, or its seconds
// converted at the demonstration's rate.
struct DemoSettings {
  SegmentationPipelineConfig config;
  double rate = 0.0;
};

DemoSettings settings_for(const FeatureMatrix& demo, const SegmentationPipelineConfig& config) {
  if (!config.seconds) return {config, 0.0};
  const double rate = sample_rate_of(demo);
  return {in_samples(config, rate), rate};
}

// The changepoint count the voting demos agree on: the most common count, held by at least 3 demos
// and by more demos than any other count; 0 = no agreement. With sensor validation only demos
// with evidence vote: a demo without any sensory event had no zone, so its count of 0 says
// nothing about the task (a dead sensor, a missed contact).
struct Agreement {
  std::size_t count = 0, votes = 0, voters = 0;
};

Agreement agreed_count(const SegmentationPipelineResult& result, bool validated) {
  std::map<std::size_t, std::size_t> votes;  // changepoint count -> demos
  Agreement a;
  for (const DemoSegmentationResult& d : result.demos) {
    if (validated && d.events.empty()) continue;
    ++votes[d.changepoints.size()];
    ++a.voters;
  }
  std::size_t runner_up = 0;
  for (const auto& [count, n] : votes) {
    if (n > a.votes) {
      runner_up = a.votes;
      a = {count, n, a.voters};
    } else {
      runner_up = std::max(runner_up, n);
    }
  }
  // A count that most demos found 0 of says nothing about where the boundaries are: the
  // changepoints of the other demos each stand on a sensory event of their own.
  if (a.votes < 3 || a.votes == runner_up || a.count == 0) a.count = 0;
  return a;
}

double log10_p_of(const DemoSegmentationResult& d, std::size_t cp) {
  for (const SplitCandidate& c : d.clasp.candidates)
    if (c.accepted && c.index == cp) return c.log10_p_value;
  return 0.0;
}

// A demo with more changepoints than agreed keeps its `k` most significant.
void prune_to(std::size_t k, const FeatureMatrix& demo, DemoSegmentationResult* out,
              std::ostringstream* msg) {
  std::vector<std::pair<double, std::size_t>> by_p;  // (log10 p, changepoint)
  for (std::size_t cp : out->changepoints) by_p.emplace_back(log10_p_of(*out, cp), cp);
  std::stable_sort(by_p.begin(), by_p.end());
  *msg << "; dropped the least significant:";
  out->changepoints.clear();
  for (std::size_t i = 0; i < by_p.size(); ++i) {
    if (i < k) {
      out->changepoints.push_back(by_p[i].second);
      continue;
    }
    out->pruned.push_back(by_p[i].second);
    *msg << " t=" << demo.time_at(by_p[i].second) << " (p=1e" << std::lround(by_p[i].first) << ")";
  }
}

// A demo with fewer changepoints than agreed takes, from the zones that hold none, ClaSP's
// best in-zone candidates that were not significant on their own but reach `log10_p` (the
// other demos' agreement is evidence too), most significant first. Only candidates of ranges
// that are still whole (no changepoint inside) count: the others were found before a split.
void fill_to(std::size_t k, double log10_p, const FeatureMatrix& demo, DemoSegmentationResult* out,
             std::ostringstream* msg) {
  std::vector<const SplitCandidate*> pool;
  for (const SplitCandidate& c : out->clasp.candidates) {
    if (c.accepted || c.log10_p_value > log10_p) continue;
    const bool whole =
        std::none_of(out->changepoints.begin(), out->changepoints.end(),
                     [&](std::size_t cp) { return c.range_begin < cp && cp < c.range_end; });
    if (whole) pool.push_back(&c);
  }
  std::stable_sort(pool.begin(), pool.end(), [](const SplitCandidate* a, const SplitCandidate* b) {
    return a->log10_p_value < b->log10_p_value;
  });
  const auto zone_of = [&](std::size_t t) -> int {
    for (std::size_t z = 0; z < out->zones.size(); ++z)
      if (out->zones[z].contains(t)) return static_cast<int>(z);
    return -1;
  };
  *msg << "; added the best in-zone candidates:";
  for (const SplitCandidate* c : pool) {
    if (out->changepoints.size() >= k) break;
    const int zone = zone_of(c->index);
    const bool taken = std::any_of(out->changepoints.begin(), out->changepoints.end(),
                                   [&](std::size_t cp) { return zone_of(cp) == zone; });
    const bool too_close =
        std::any_of(out->changepoints.begin(), out->changepoints.end(), [&](std::size_t cp) {
          return (cp > c->index ? cp - c->index : c->index - cp) < out->min_segment_length;
        });
    if (zone < 0 || taken || too_close) continue;
    out->changepoints.push_back(c->index);
    out->added.push_back(c->index);
    *msg << " t=" << demo.time_at(c->index) << " (p=1e" << std::lround(c->log10_p_value) << ")";
  }
  std::sort(out->changepoints.begin(), out->changepoints.end());
  std::sort(out->added.begin(), out->added.end());
}

// SegmentationPipelineConfig::consensus_count: demos of one task hold the same skills.
void agree_on_count(const std::vector<FeatureMatrix>& demos, bool validated, double fill_p,
                    SegmentationPipelineResult* result) {
  const Agreement a = agreed_count(*result, validated);
  if (a.count == 0) return;
  for (std::size_t d = 0; d < result->demos.size(); ++d) {
    DemoSegmentationResult& out = result->demos[d];
    const std::size_t had = out.changepoints.size();
    if (had == a.count || (had < a.count && !(fill_p > 0.0 && validated))) continue;
    std::ostringstream msg;
    msg << demo_context(d) << ": " << had << " changepoints where " << a.votes << " of the "
        << a.voters << " voting demonstrations have " << a.count;
    if (had > a.count)
      prune_to(a.count, demos[d], &out, &msg);
    else
      fill_to(a.count, std::log10(fill_p), demos[d], &out, &msg);
    if (out.changepoints.size() == had && out.pruned.empty()) continue;  // nothing to add
    std::sort(out.changepoints.begin(), out.changepoints.end());
    std::sort(out.pruned.begin(), out.pruned.end());
    out.changepoint_times.clear();
    out.pruned_times.clear();
    out.added_times.clear();
    for (std::size_t cp : out.changepoints) out.changepoint_times.push_back(demos[d].time_at(cp));
    for (std::size_t cp : out.pruned) out.pruned_times.push_back(demos[d].time_at(cp));
    for (std::size_t cp : out.added) out.added_times.push_back(demos[d].time_at(cp));
    result->warnings.push_back(msg.str());
  }
}

}  // namespace

namespace {
std::size_t samples(double seconds, double rate, std::size_t at_least) {
  return std::max<std::size_t>(at_least, static_cast<std::size_t>(std::lround(seconds * rate)));
}
}  // namespace

SegmentationPipelineConfig in_samples(const SegmentationPipelineConfig& config, double rate) {
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

double sample_rate_of(const FeatureMatrix& demo) {
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

SegmentationPipelineResult run_segmentation_pipeline(
    const std::vector<FeatureMatrix>& demos, const std::vector<std::string>& sensor_features,
    const SegmentationPipelineConfig& config, const std::vector<std::string>& state_features) {
  if (demos.empty()) throw std::invalid_argument("no demonstrations to segment");
  SegmentationPipelineResult result;

  // ---- input checks: shape, same features, roles, finite samples, lengths
  for (std::size_t d = 0; d < demos.size(); ++d) {
    try {
      demos[d].validate_shape();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demo_context(d) + ": " + e.what());
    }
    if (demos[d].rows() < 2) {
      throw std::invalid_argument(demo_context(d) + " has " + std::to_string(demos[d].rows()) +
                                  " samples; at least 2 are needed");
    }
  }
  check_same_features(demos);
  const FeatureMatrix& first = demos[0];
  for (const std::string& s : sensor_features) {
    if (first.index_of(s) < 0) {
      throw std::invalid_argument("sensor feature '" + s + "' is not in the demonstrations");
    }
  }
  if (state_features.empty()) {
    for (const std::string& name : first.names) {
      if (std::find(sensor_features.begin(), sensor_features.end(), name) == sensor_features.end())
        result.state_features.push_back(name);
    }
  } else {
    for (const std::string& s : state_features) {
      if (first.index_of(s) < 0) {
        throw std::invalid_argument("state feature '" + s + "' is not in the demonstrations");
      }
    }
    result.state_features = state_features;
  }
  result.sensor_features = sensor_features;
  if (result.state_features.empty()) {
    throw std::invalid_argument("no state feature to segment (every feature is a sensor)");
  }
  std::vector<std::string> used = result.state_features;
  used.insert(used.end(), sensor_features.begin(), sensor_features.end());
  for (std::size_t d = 0; d < demos.size(); ++d)
    check_finite(demos[d].select(used), demo_context(d));

  std::vector<DemoSettings> settings;
  for (std::size_t d = 0; d < demos.size(); ++d) {
    try {
      settings.push_back(settings_for(demos[d], config));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(demo_context(d) + ": " + e.what());
    }
    const std::size_t min_s = settings.back().config.segmentation.min_segment_length;
    if (min_s > 0 && static_cast<std::size_t>(demos[d].rows()) < 2 * min_s) {
      throw std::invalid_argument(demo_context(d) + " has " + std::to_string(demos[d].rows()) +
                                  " samples, fewer than 2 * min_s = " + std::to_string(2 * min_s));
    }
  }

  // ---- constant state features carry no information
  std::vector<std::string> informative;
  for (const std::string& name : result.state_features) {
    bool constant_everywhere = true;
    for (const FeatureMatrix& demo : demos) {
      constant_everywhere = constant_everywhere && is_constant(demo, demo.require(name));
    }
    if (constant_everywhere) {
      result.warnings.push_back("state feature '" + name +
                                "' is constant in every demonstration and is ignored");
    } else {
      informative.push_back(name);
    }
  }
  if (informative.empty()) {
    throw std::invalid_argument("every state feature is constant: nothing to segment");
  }

  // ---- II-B feature relevance (needs >= 2 demonstrations)
  const auto relevance_start = std::chrono::steady_clock::now();
  if (demos.size() >= 2) {
    FeatureRelevanceConfig relevance_config = config.relevance;
    relevance_config.threads = config.threads;
    result.relevance = compute_feature_relevance(demos, informative, relevance_config);
    result.relevance_computed = true;
    for (const std::string& w : result.relevance.warnings) result.warnings.push_back(w);
    result.selected_features = result.relevance.selected;
    for (double score : result.relevance.selected_scores()) {
      // Weights must be positive; a non-positive best score (warned above) keeps weight 1.
      result.feature_weights.push_back(score > 0 ? score : 1.0);
    }
    if (result.selected_features.empty()) {
      throw std::invalid_argument("feature relevance selected no feature");
    }
  } else {
    result.warnings.push_back(
        "a single demonstration: feature relevance needs at least 2, so every non-constant "
        "state feature is used with equal weights");
    result.selected_features = informative;
    result.feature_weights.assign(informative.size(), 1.0);
  }

  const auto segmentation_start = std::chrono::steady_clock::now();
  result.relevance_seconds =
      std::chrono::duration<double>(segmentation_start - relevance_start).count();

  // ---- II-C multivariate ClaSP + sensory validation, one demonstration per worker
  const bool validate = config.validate_with_sensors && !sensor_features.empty();
  if (!validate) {
    result.warnings.push_back(sensor_features.empty()
                                  ? "no sensor features: ClaSP changepoints are not validated"
                                  : "sensor validation disabled: ClaSP changepoints are accepted");
  }
  const std::vector<std::size_t> groups = sensor_groups(sensor_features);
  result.demos.resize(demos.size());
  for_each_demo(demos.size(), config.threads, [&](std::size_t d) {
    const FeatureMatrix& demo = demos[d];
    DemoSegmentationResult& out = result.demos[d];
    out.num_samples = static_cast<std::size_t>(demo.rows());
    out.sample_rate = settings[d].rate;
    const Eigen::MatrixXd state = demo.select(result.selected_features).data;
    const SegmentationPipelineConfig& own = settings[d].config;
    MultivariateSegmentationConfig demo_config = own.segmentation;
    if (own.window_size > 0)
      demo_config.window_sizes.assign(result.selected_features.size(), own.window_size);
    // Events do not depend on min_s: detected once, for the zone-guided search and validation.
    const SensorEvents events =
        validate ? detect_sensor_events(demo.select(sensor_features).data, own.events, groups)
                 : SensorEvents{};
    const auto zones = [&](std::size_t min_s) {
      return confidence_zones(events.all, min_s, static_cast<std::size_t>(demo.rows()));
    };
    if (validate && config.search_in_zones) {
      demo_config.candidate_zones_for = zones;
      if (config.anchor_to_events) {
        for (const SensoryEvent& e : events.details) {
          demo_config.zone_anchors.push_back(e.index);
          demo_config.preferred_anchors.push_back(e.rest_edge);
        }
      }
    }
    out.clasp = segment_multivariate(state, result.feature_weights, demo_config);
    out.min_segment_length = out.clasp.min_segment_length;
    if (validate) {
      const ChangepointValidation v =
          validate_with_zones(out.clasp.changepoints, zones(out.min_segment_length));
      out.changepoints = v.accepted;
      out.rejected = v.rejected;
      out.zones = v.zones;
      out.events = events.all;
      out.event_details = events.details;
    } else {
      out.changepoints = out.clasp.changepoints;
    }
    for (std::size_t cp : out.changepoints) out.changepoint_times.push_back(demo.time_at(cp));
    for (std::size_t cp : out.rejected) out.rejected_times.push_back(demo.time_at(cp));
  });
  if (config.consensus_count)
    agree_on_count(demos, validate, config.consensus_fill_p_value, &result);
  result.segmentation_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - segmentation_start).count();
  for (std::size_t d = 0; d < demos.size() && validate; ++d) {
    for (const std::string& sensor : sensor_features) {
      if (is_constant(demos[d], demos[d].require(sensor)))
        result.warnings.push_back(demo_context(d) + ": sensor '" + sensor +
                                  "' is constant (dead or disconnected?): no zone from it");
    }
  }
  for (std::size_t d = 0; d < demos.size(); ++d) {
    if (validate && result.demos[d].events.empty()) {
      result.warnings.push_back(demo_context(d) +
                                ": no sensory event detected, so no changepoint can be validated");
    }
  }
  return result;
}

}  // namespace lfd
