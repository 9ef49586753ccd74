// signature: learns the sensory signature of segmented demonstrations (lfd_core/
// sensory_signature.hpp) and scores runs against it, offline; prints JSON.
//   signature [--topics YAML] --demo FILE --boundaries T1,T2,... [--demo ...] --run FILE
//             --boundaries ... [--channels a,b] [--sensor-columns a,b]
// A failed reproduction should score above 1 on the segment where it failed; a nominal one stays
// below 1 everywhere (the executor applies the same rule live).
#include <cmath>
#include <iostream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "lfd_core/dmp/sensory_signature.hpp"
#include "lfd_core/io/user_text.hpp"
#include "lfd_segmentation/bag_features.hpp"
#include "lfd_segmentation/cli_args.hpp"
#include "lfd_segmentation/csv_features.hpp"
#include "lfd_segmentation/segmentation_params.hpp"

#ifndef LFD_CONFIG_DIR
#define LFD_CONFIG_DIR "config"
#endif

namespace {

using lfd_segmentation::splitList;

const char* const kUsage =
    R"(usage: signature [options] --demo FILE --boundaries LIST ... --run FILE --boundaries LIST ...
  --demo FILE               a demonstration: a bag, a.bag,b.bag,... (one demo in parts) or a CSV
  --run FILE                a run to score (same kinds of file)
  --boundaries T1,T2,...    the preceding --demo's or --run's segment boundaries, s from its first
                            sample (every file the same number)
  --topics PATH             YAML 'topics:' list for bags (default: the config's)
  --config PATH             parameters (default: )" LFD_CONFIG_DIR
    R"(/segmentation.yaml): rate, limits
  --channels a,b,c          features to monitor (default: the sensor-role features of the topics,
                            or of --sensor-columns for CSV files)
  --sensor-columns a,b,c    CSV: the sensor columns
  --time-column NAME        CSV time column
Prints JSON: per run, per segment, every channel's score (> 1 = outside what the demonstrations
showed) and the worst deviation (channel, time, phase, expected and measured level).
)";

struct Recording {
  std::string file;
  std::vector<double> boundaries;
  bool is_run = false;
};

struct Options {
  std::string config = std::string(LFD_CONFIG_DIR) + "/segmentation.yaml";
  std::string topics, time_column;
  std::vector<std::string> channels, sensors;
  std::vector<Recording> recordings;
};

std::vector<double> parseTimes(const std::string& list) {
  std::vector<double> out;
  for (const std::string& item : splitList(list)) {
    std::size_t used = 0;
    double t = NAN;
    try {
      t = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != item.size() || !std::isfinite(t))
      throw std::invalid_argument("--boundaries expects seconds, got " + lfd::quoted(item));
    out.push_back(t);
  }
  return out;
}

Options parseArgs(int argc, char** argv) {
  Options o;
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    auto value = [&] { return lfd_segmentation::optionValue(argc, argv, &k); };
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      std::exit(0);
    } else if (arg == "--demo" || arg == "--run") {
      o.recordings.push_back({value(), {}, arg == "--run"});
    } else if (arg == "--boundaries") {
      if (o.recordings.empty()) throw std::invalid_argument("--boundaries before any --demo");
      o.recordings.back().boundaries = parseTimes(value());
    } else if (arg == "--topics") {
      o.topics = value();
    } else if (arg == "--config") {
      o.config = value();
    } else if (arg == "--channels") {
      o.channels = splitList(value());
    } else if (arg == "--sensor-columns") {
      o.sensors = splitList(value());
    } else if (arg == "--time-column") {
      o.time_column = value();
    } else {
      throw std::invalid_argument("unknown argument " + lfd::quoted(arg) + "\n" + kUsage);
    }
  }
  return o;
}

nlohmann::json deviationJson(const lfd::Deviation& d) {
  return {{"channel", d.channel_name}, {"time", d.time},         {"phase", d.phase},
          {"expected", d.expected},    {"measured", d.measured}, {"score", d.score}};
}

nlohmann::json run(const Options& o) {
  lfd_segmentation::SegmentationParams params = lfd_segmentation::loadParamsFile(o.config);
  if (!o.topics.empty()) params.topics = lfd_segmentation::loadParamsFile(o.topics).topics;
  std::vector<lfd::SegmentedRecording> demos, runs;
  std::vector<std::string> channels = o.channels, run_files;
  for (const Recording& r : o.recordings) {
    lfd::SegmentedRecording rec;
    rec.boundaries = r.boundaries;
    if (lfd_segmentation::endsWith(r.file, ".bag")) {
      auto features =
          lfd_segmentation::readBagFeatures(r.file, params.topics, params.rate, params.limits);
      if (channels.empty()) channels = features.sensor_features;
      rec.features = std::move(features.matrix);
    } else {
      rec.features = lfd_segmentation::readCsvFeatures(r.file, o.time_column, 0.0, params.limits);
      if (channels.empty()) channels = o.sensors;
    }
    (r.is_run ? runs : demos).push_back(std::move(rec));
    if (r.is_run) run_files.push_back(r.file);
  }
  if (channels.empty())
    throw std::invalid_argument("no channel to monitor: give --channels or sensor features");
  const lfd::SensorySignature signature = lfd::learnSignature(demos, channels);
  nlohmann::json out = {{"channels", channels}, {"demonstrations", demos.size()}, {"runs", {}}};
  for (const lfd::SegmentSignature& s : signature.segments) {
    nlohmann::json thresholds;
    for (const lfd::ChannelSignature& c : s.channels) thresholds.push_back(c.threshold);
    out["segments"].push_back({{"duration_mean", s.duration_mean},
                               {"duration_spread", s.duration_spread},
                               {"thresholds", thresholds}});
  }
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::vector<lfd::Deviation> worst;
    const auto scores = lfd::scoreRecording(signature, runs[k], &worst);
    nlohmann::json segments;
    for (std::size_t s = 0; s < scores.size(); ++s)
      segments.push_back({{"scores", scores[s]}, {"worst", deviationJson(worst[s])}});
    out["runs"].push_back({{"file", run_files[k]}, {"segments", segments}});
  }
  out["success"] = true;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::cout
        << run(parseArgs(argc, argv)).dump(1, ' ', false, nlohmann::json::error_handler_t::replace)
        << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "signature: error: " << e.what() << "\n";
    std::cout << nlohmann::json({{"success", false}, {"error", e.what()}})
                     .dump(1, ' ', false, nlohmann::json::error_handler_t::replace)
              << "\n";
    return 1;
  }
}
