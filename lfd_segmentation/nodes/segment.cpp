// segment: master-free command-line segmentation of bags or CSV files; prints JSON.
//   segment [options] FILE...
// One CSV file without --sensor-columns: plain parameter-free multivariate ClaSP over all columns.
// Otherwise the full pipeline across the files (feature relevance, weighted ClaSP, sensor
// validation). Bags use the topics/roles of --config; CSV columns are state features except the
// --sensor-columns.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "lfd_core/io/safe_paths.hpp"
#include "lfd_core/io/user_text.hpp"
#include "lfd_segmentation/bag_features.hpp"
#include "lfd_segmentation/cli_args.hpp"
#include "lfd_segmentation/csv_features.hpp"
#include "lfd_segmentation/segmentation_json.hpp"
#include "lfd_segmentation/segmentation_params.hpp"

#ifndef LFD_CONFIG_DIR
#define LFD_CONFIG_DIR "config"
#endif

namespace {

using lfd_segmentation::endsWith;
using lfd_segmentation::splitList;

const char* const kUsage = R"(usage: segment [options] FILE...
  FILE                      demonstration bags (*.bag) or CSV files (header row, one row per sample);
                            a.bag,b.bag,... = one demonstration recorded in several bags, in order
  --config PATH             parameters (default: )" LFD_CONFIG_DIR R"(/segmentation.yaml)
  --topics PATH             YAML whose 'topics:' list (topic, role, fields) replaces the config's:
                            another robot's bags without editing the parameters
  --list-fields             print every topic of the bag(s) and its numeric field paths, then exit
  --sensor-columns a,b,c    CSV columns used only for the confidence zones
  --state-columns a,b,c     CSV columns considered for segmentation (default: all other columns)
  --time-column NAME        CSV time column (default: time, t, timestamp or stamp if present)
  --rate HZ                 bag resampling rate / CSV sample rate (overrides a CSV time column)
  --resample HZ             CSV: average the rows onto a clock of HZ (a 1 kHz F/T: 100); the
                            segmentation is in seconds, so only speed and the sample limits change.
                            Without it, demos over the sample limits go onto the fastest clock
                            that fits (warned)
  --combination NAME[,NAME] average | product | weighted_average | weighted_product |
                            distance_average | weighted_distance_average, or 'all'. Several: the
                            features are selected once and the JSON holds one result per name
                            under "methods" (the selection does not depend on the combination)
  --procedure NAME          joint (all demos together: every kind of evidence, agreed by DTW) |
                            zone_search (zones first, changepoints on their events) |
                            paper (the paper's: paper_candidates anywhere, then the zone filter);
                            default: the config's 'procedure' (the shipped one: joint)
  --threshold T             relevance threshold in (0,1]
  --min-segment-seconds S   min segment length min_s (s)
  --window-seconds S        fixed ClaSP window (s)
  --num-changepoints N      exact number of ClaSP changepoints (default: significance test)
  --threads N               worker threads (default: parameter 'threads')
  --feature-profiles        include every selected feature's ClaSP profile
  --no-profiles             omit the combined profiles
  --features                include what was segmented: "feature_matrices", per demo its clock
                            "time" (s, as the changepoint times) and every feature's "name",
                            "role" (state, sensor or context) and "values" (rounded to 1e-6 of
                            the feature's range); plot_segmentation.py draws them
  --timing                  report the stage timings (stderr and "timing" in the JSON)
  --output PATH             write the JSON there instead of stdout
)";

std::vector<lfd::ProfileCombination> parseCombinations(const std::string& list) {
  std::vector<lfd::ProfileCombination> out;
  if (list == "all") {
    for (const char* name : {"average", "product", "weighted_average", "weighted_product",
                             "distance_average", "weighted_distance_average"})
      out.push_back(lfd::parseProfileCombination(name));
    return out;
  }
  for (const std::string& name : splitList(list)) {
    const lfd::ProfileCombination c = lfd::parseProfileCombination(name);
    if (std::find(out.begin(), out.end(), c) != out.end())
      throw std::invalid_argument("--combination names " + lfd::quoted(name) + " twice");
    out.push_back(c);
  }
  return out;
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

struct Options {
  std::string config = std::string(LFD_CONFIG_DIR) + "/segmentation.yaml";
  std::string topics;  ///< --topics: a YAML file with the topics list
  bool list_fields = false;
  std::vector<std::string> files, sensors, states;
  std::string time_column, combination, output, procedure;
  double rate = 0, resample = 0, threshold = 0, min_seconds = 0, window_seconds = 0;
  long num_changepoints = 0, threads = -1;
  bool timing = false, feature_profiles = false, profiles = true, features = false;
};

Options parseArgs(int argc, char** argv) {
  Options o;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    auto value = [&] { return lfd_segmentation::optionValue(argc, argv, &k); };
    auto number = [&]() -> double {
      const std::string v = value();
      try {
        std::size_t used = 0;
        const double x = std::stod(v, &used);
        if (used != v.size()) throw std::invalid_argument("");
        return x;
      } catch (const std::exception&) {
        throw std::invalid_argument(arg + " expects a number, got " + lfd::quoted(v));
      }
    };
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      std::exit(0);
    } else if (arg == "--config") {
      o.config = value();
    } else if (arg == "--topics") {
      o.topics = value();
    } else if (arg == "--list-fields") {
      o.list_fields = true;
    } else if (arg == "--sensor-columns") {
      o.sensors = splitList(value());
    } else if (arg == "--state-columns") {
      o.states = splitList(value());
    } else if (arg == "--time-column") {
      o.time_column = value();
    } else if (arg == "--rate") {
      o.rate = number();
    } else if (arg == "--resample") {
      o.resample = number();
      if (!(o.resample > 0) || !std::isfinite(o.resample))
        throw std::invalid_argument("--resample must be a rate > 0 (Hz)");
    } else if (arg == "--combination") {
      o.combination = value();
    } else if (arg == "--procedure") {
      o.procedure = value();
    } else if (arg == "--threshold") {
      o.threshold = number();
    } else if (arg == "--min-segment-seconds") {
      o.min_seconds = number();
    } else if (arg == "--window-seconds") {
      o.window_seconds = number();
    } else if (arg == "--num-changepoints") {
      o.num_changepoints = static_cast<long>(number());
    } else if (arg == "--threads") {
      o.threads = static_cast<long>(number());
    } else if (arg == "--timing") {
      o.timing = true;
    } else if (arg == "--feature-profiles") {
      o.feature_profiles = true;
    } else if (arg == "--features") {
      o.features = true;
    } else if (arg == "--no-profiles") {
      o.profiles = false;
    } else if (arg == "--output") {
      o.output = value();
    } else if (!arg.empty() && arg[0] == '-') {
      throw std::invalid_argument("unknown option " + arg + "\n" + kUsage);
    } else {
      o.files.push_back(arg);
    }
  }
  if (o.files.empty()) throw std::invalid_argument(std::string("no input files\n") + kUsage);
  if (!(o.min_seconds >= 0) || !(o.window_seconds >= 0) || !(o.rate >= 0) ||
      !std::isfinite(o.rate)) {
    throw std::invalid_argument("--min-segment-seconds, --window-seconds and --rate must be >= 0");
  }
  return o;
}

// --resample: the clock's span is checked against the per-demo sample limit before anything is
// allocated (a time column in milliseconds read as seconds would ask for 1000 times the rows).
lfd::FeatureMatrix resampleWithinLimits(const lfd::FeatureMatrix& m, double rate,
                                        const std::string& path,
                                        const lfd_segmentation::SegmentationParams& params) {
  const double span = m.time.empty() ? 0.0 : m.time.back() - m.time.front();
  const double rows = span * rate + 1.0;
  if (!(rows <= static_cast<double>(params.limits.max_samples_per_demo)))
    throw std::invalid_argument(lfd::quoted(path) + " spans " + std::to_string(span) +
                                " s: at --resample " + std::to_string(rate) +
                                " Hz that is over the limit of " +
                                std::to_string(params.limits.max_samples_per_demo) +
                                " samples (limits/max_samples_per_demo)");
  try {
    return lfd::resample(m, rate);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(lfd::quoted(path) + ": " + e.what());
  }
}

// Every input file read (all bags or all CSV), with the feature roles and the clock warnings.
struct LoadedDemos {
  bool bags = false;
  std::vector<lfd::FeatureMatrix> demos;
  std::vector<std::string> sensors, states, clock_warnings;
};

// CSV demos too fine-grained for the sample limits (a 1 kHz F/T over 20 s) are averaged onto the
// fastest whole-Hz clock that fits them all, with a warning: the segmentation is in seconds, so
// only its speed changes. --resample HZ chooses the clock instead.
void fitCsvClocks(const lfd_segmentation::SegmentationParams& params,
                  const std::vector<std::string>& files, LoadedDemos* in) {
  const lfd_segmentation::RequestLimits& lim = params.limits;
  std::size_t most_rows = 0, total_rows = 0;
  double longest = 0.0, total_span = 0.0;
  for (const lfd::FeatureMatrix& m : in->demos) {
    const std::size_t rows = static_cast<std::size_t>(m.rows());
    const double span = m.time.empty() ? 0.0 : m.time.back() - m.time.front();
    most_rows = std::max(most_rows, rows);
    total_rows += rows;
    longest = std::max(longest, span);
    total_span += span;
  }
  if ((most_rows <= lim.max_samples_per_demo && total_rows <= lim.max_total_samples) ||
      !(longest > 0.0))
    return;
  const double demos = static_cast<double>(in->demos.size());
  const double rate =
      std::floor(std::min((static_cast<double>(lim.max_samples_per_demo) - 1.0) / longest,
                          (static_cast<double>(lim.max_total_samples) - demos) / total_span));
  if (!(rate >= 1.0)) return;  // checkDemosFit names the limit
  for (std::size_t d = 0; d < in->demos.size(); ++d)
    in->demos[d] = resampleWithinLimits(in->demos[d], rate, files[d], params);
  std::ostringstream note;
  note << "the CSV demos (up to " << most_rows << " rows in one, " << total_rows
       << " in all) were averaged onto a " << rate
       << " Hz clock to fit limits/max_samples_per_demo and limits/max_total_samples; "
          "--resample HZ chooses the clock";
  in->clock_warnings.push_back(note.str());
}

// The shipped configuration with the command line's overrides.
lfd_segmentation::SegmentationParams paramsFor(const Options& o) {
  lfd_segmentation::SegmentationParams params = lfd_segmentation::loadParamsFile(o.config);
  if (!o.topics.empty()) {
    params.topics = lfd_segmentation::loadParamsFile(o.topics).topics;
    if (params.topics.empty()) throw std::invalid_argument(o.topics + " has no 'topics:' list");
  }
  if (o.rate > 0) params.rate = o.rate;
  const std::vector<lfd::ProfileCombination> combinations = parseCombinations(o.combination);
  if (combinations.size() == 1) params.pipeline.segmentation.combination = combinations[0];
  if (!o.procedure.empty())
    params.pipeline.procedure = lfd::parseSegmentationProcedure(o.procedure);
  if (o.threshold != 0) {
    if (!(o.threshold > 0 && o.threshold <= 1))
      throw std::invalid_argument("--threshold must be in (0,1]");
    params.pipeline.relevance.threshold = o.threshold;
  }
  lfd_segmentation::checkSecondsOverride(o.min_seconds, "--min-segment-seconds", params.limits);
  lfd_segmentation::checkSecondsOverride(o.window_seconds, "--window-seconds", params.limits);
  if (o.min_seconds > 0) params.min_segment_seconds = o.min_seconds;
  if (o.window_seconds > 0) params.window_seconds = o.window_seconds;
  if (o.threads >= 0) params.pipeline.threads = static_cast<int>(o.threads);
  return params;
}

LoadedDemos loadDemos(const Options& o, const lfd_segmentation::SegmentationParams& params) {
  LoadedDemos in;
  std::size_t bags = 0;
  for (const std::string& f : o.files) bags += endsWith(f, ".bag") ? 1 : 0;
  if (bags != 0 && bags != o.files.size())
    throw std::invalid_argument("do not mix bags and CSV files");
  in.bags = bags != 0;
  // The CLI skips the roots (its user owns the shell) but not the budget.
  lfd_segmentation::checkRequestBudget(o.files, params.limits, lfd::PathPolicy{},
                                       in.bags ? "bag" : "CSV");
  if (in.bags && o.resample > 0)
    throw std::invalid_argument("--resample is for CSV files: a bag's clock is set by --rate");
  in.sensors = o.sensors;
  in.states = o.states;
  for (const std::string& f : o.files) {
    if (in.bags) {
      lfd_segmentation::DemoFeatures demo =
          lfd_segmentation::readBagFeatures(f, params.topics, params.rate, params.limits);
      if (in.demos.empty() && o.sensors.empty()) in.sensors = demo.sensor_features;
      if (in.demos.empty() && o.states.empty()) in.states = demo.state_features;
      in.clock_warnings.insert(in.clock_warnings.end(), demo.warnings.begin(), demo.warnings.end());
      in.demos.push_back(std::move(demo.matrix));
      continue;
    }
    in.demos.push_back(lfd_segmentation::readCsvFeatures(f, o.time_column, o.rate, params.limits));
    if (in.demos.back().time.empty())
      throw std::invalid_argument(
          "CSV file " + lfd::quoted(f) +
          " has no time column (time, t, timestamp, stamp or --time-column): give its sample "
          "rate with --rate, the time parameters are in seconds");
    if (o.resample > 0)
      in.demos.back() = resampleWithinLimits(in.demos.back(), o.resample, f, params);
    const std::string gap = lfd_segmentation::clockGapWarning(in.demos.back(), f);
    if (!gap.empty()) in.clock_warnings.push_back(gap);
  }
  if (!in.bags && !(o.resample > 0)) fitCsvClocks(params, o.files, &in);
  lfd_segmentation::checkDemosFit(params, in.demos, o.files);
  return in;
}

// The segmentation's JSON, and the columns it used as states and as sensors.
struct Segmented {
  nlohmann::json out;
  std::vector<std::string> states, sensors;
};

// One CSV without sensors: plain parameter-free multivariate ClaSP over the chosen columns.
Segmented segmentSingleSeries(const Options& o, const LoadedDemos& in,
                              const lfd::SegmentationPipelineConfig& config,
                              const lfd_segmentation::JsonOptions& json_options) {
  lfd::FeatureMatrix demo = in.states.empty() ? in.demos[0] : in.demos[0].select(in.states);
  lfd::checkFinite(demo, o.files[0]);
  const lfd::SegmentationPipelineConfig own = lfd::inSamples(config, lfd::sampleRateOf(demo));
  lfd::MultivariateSegmentationConfig seg = own.segmentation;
  if (own.window_size > 0) seg.window_sizes.assign(demo.cols(), own.window_size);
  const lfd::MultivariateSegmentation s = lfd::segmentMultivariate(demo.data, {}, seg);
  Segmented r{lfd_segmentation::toJson(s, demo, o.files[0], json_options), demo.names, {}};
  r.out["mode"] = "clasp";
  return r;
}

// Several combinations: the features are selected once, each combination segments them.
Segmented segmentEachCombination(const Options& o, const LoadedDemos& in,
                                 const lfd::SegmentationPipelineConfig& config,
                                 const std::vector<lfd::ProfileCombination>& combinations,
                                 const lfd_segmentation::JsonOptions& json_options) {
  const lfd::PreparedSegmentation prepared =
      lfd::prepareSegmentation(in.demos, in.sensors, config, in.states);
  Segmented r{nlohmann::json::object(), prepared.base.state_features,
              prepared.base.sensor_features};
  r.out["methods"] = nlohmann::json::object();
  for (lfd::ProfileCombination c : combinations) {
    lfd::SegmentationPipelineConfig own = config;
    own.segmentation.combination = c;
    r.out["methods"][lfd::toString(c)] = lfd_segmentation::toJson(
        lfd::segmentPrepared(prepared, in.demos, own), in.demos, o.files, json_options);
  }
  r.out["mode"] = "pipeline";
  return r;
}

Segmented segment(const Options& o, const LoadedDemos& in,
                  const lfd::SegmentationPipelineConfig& config) {
  const std::vector<lfd::ProfileCombination> combinations = parseCombinations(o.combination);
  lfd_segmentation::JsonOptions json_options;
  json_options.profiles = o.profiles;
  json_options.feature_profiles = o.feature_profiles;
  if (!in.bags && in.demos.size() == 1 && o.sensors.empty()) {
    if (combinations.size() > 1)
      throw std::invalid_argument(
          "several combinations need the pipeline (bags, several CSV files or --sensor-columns)");
    return segmentSingleSeries(o, in, config, json_options);
  }
  if (combinations.size() > 1)
    return segmentEachCombination(o, in, config, combinations, json_options);
  const lfd::SegmentationPipelineResult r =
      lfd::runSegmentationPipeline(in.demos, in.sensors, config, in.states);
  Segmented s{lfd_segmentation::toJson(r, in.demos, o.files, json_options), r.state_features,
              r.sensor_features};
  s.out["mode"] = "pipeline";
  return s;
}

nlohmann::json timingJson(const std::vector<lfd::FeatureMatrix>& demos, double load_time,
                          double compute_time, double total_time) {
  std::size_t samples = 0;
  for (const auto& d : demos) samples += d.rows();
  std::cerr << "segment: " << demos.size() << " demo(s), " << demos[0].cols() << " features, "
            << samples << " samples: load " << load_time << " s, segmentation " << compute_time
            << " s, total " << total_time << " s\n";
  return {{"load_s", load_time},   {"segmentation_s", compute_time}, {"total_s", total_time},
          {"demos", demos.size()}, {"features", demos[0].cols()},    {"samples", samples}};
}

nlohmann::json run(const Options& o) {
  const auto start = std::chrono::steady_clock::now();
  const lfd_segmentation::SegmentationParams params = paramsFor(o);
  lfd::SegmentationPipelineConfig config = params.pipelineConfig();
  if (o.num_changepoints > 0)
    config.segmentation.num_changepoints = static_cast<int>(o.num_changepoints);
  const LoadedDemos in = loadDemos(o, params);
  const double load_time = secondsSince(start);
  const auto compute_start = std::chrono::steady_clock::now();
  Segmented s = segment(o, in, config);
  const double compute_time = secondsSince(compute_start);
  nlohmann::json& out = s.out;
  if (o.features)
    out["feature_matrices"] = lfd_segmentation::featureMatricesJson(in.demos, s.states, s.sensors);
  if (o.timing) out["timing"] = timingJson(in.demos, load_time, compute_time, secondsSince(start));
  for (const std::string& w : in.clock_warnings) {
    out["warnings"].push_back(w);
    std::cerr << "segment: warning: " << w << "\n";
  }
  out["success"] = true;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  nlohmann::json out;
  int status = 0;
  try {
    options = parseArgs(argc, argv);
    if (options.list_fields) {
      for (const std::string& f : options.files) std::cout << lfd_segmentation::describeBag(f);
      return 0;
    }
    out = run(options);
  } catch (const std::exception& e) {
    std::cerr << "segment: error: " << e.what() << "\n";
    out = {{"success", false}, {"error", e.what()}};
    status = 1;
    // A command line that did not parse still names its --output: the error goes there, where
    // the caller reads the answer (not a stale file of an earlier run).
    for (int k = 1; options.output.empty() && k + 1 < argc; ++k)
      if (std::string(argv[k]) == "--output") options.output = argv[k + 1];
  }
  out["format"] = lfd_segmentation::kSegmentationResultFormat;
  const std::string text = lfd_segmentation::dumpJson(out);
  if (!options.output.empty()) {
    // A result file: replaced on every run (scripts rerun into their folder), but atomically,
    // never over one of the inputs and only over a result file of its own.
    try {
      const lfd::OutputKind kind = lfd_segmentation::segmentationResultOutput();
      lfd::writeTextAtomically(lfd::checkOutputFile(options.output, {}, true, options.files, kind),
                               true, kind, text + "\n");
    } catch (const std::exception& e) {
      std::cerr << "segment: cannot write the output: " << e.what() << "\n";
      return 1;
    }
  } else {
    std::cout << text << "\n";
  }
  return status;
}
