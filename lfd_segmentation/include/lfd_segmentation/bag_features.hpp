// Demonstration bag -> feature matrix: every configured topic field becomes one named feature
// ("<topic>/<field>", e.g. /ee_twist/twist/linear/x), resampled onto one clock. Any message type:
// fields are read by path with the message definitions stored in the bag (lfd_core's
// ros_message_reader.hpp gives the path syntax: nested fields, array indices, names looked up in a
// name/names/*_names array, "<vector>/norm", and "*" expanded over the first message). Sample times
// are the header stamps, the bag receive time when a message has no header or a zero stamp.
// A demonstration may be recorded in several bag files: "a.bag,b.bag,c.bag" reads them in order as
// one demonstration, on their own (absolute) stamps, so gaps between the files stay gaps.
#pragma once

#include <string>
#include <vector>

#include "lfd_core/io/safe_paths.hpp"
#include "lfd_core/segmentation/time_series.hpp"
#include "lfd_segmentation/segmentation_params.hpp"

namespace lfd_segmentation {

struct DemoFeatures {
  std::string source;         ///< bag path
  lfd::FeatureMatrix matrix;  ///< resampled features, times = bag times (s)
  std::vector<std::string> state_features;
  std::vector<std::string> sensor_features;
  std::vector<std::string> context_features;  ///< role context: in the matrix, used by neither
  std::vector<std::string> warnings;  ///< stamps out of order, duplicated, with gaps (per topic)
};

/// The bag files of one demonstration: `path` itself, or its comma-separated parts (unless a file
/// of that very name exists).
std::vector<std::string> demoParts(const std::string& path);

/// One demonstration's bag files, each opened once by the file-access layer: the reader reads
/// these descriptors, and their identities (lfd::FileIdentity) key the service's cache, so a key
/// always describes the very files that were read.
struct DemoFiles {
  std::string path;                ///< as the request gave it
  std::vector<std::string> names;  ///< demoParts(path), for messages
  std::vector<lfd::InputFile> parts;
};

/// Opens the parts of `path` under `policy`. Throws std::runtime_error "cannot open bag ...: why".
DemoFiles openDemoFiles(const std::string& path, const lfd::PathPolicy& policy = {});

/// The request budget of the segmentation (service and CLI), checked before anything is read:
/// `entries` (bag paths or CSV files) within limits/max_bags, the files they expand to (demo
/// parts) within limits/max_bag_files, their total size within limits/max_total_bytes, and each
/// one a regular file inside `paths`' roots. Throws std::invalid_argument naming the key, or for
/// a file "cannot open <kind>: ..." and why.
void checkRequestBudget(const std::vector<std::string>& entries, const RequestLimits& limits,
                        const lfd::PathPolicy& paths, const std::string& kind = "bag");

/// Raw (not resampled) streams of the configured fields of one bag. Throws std::runtime_error for
/// unreadable/truncated bags or messages that do not match their definition (naming the file,
/// topic, declared type and the message's index and time), and std::invalid_argument for a
/// missing topic, a field that does not exist (listing the topic's numeric fields), a field no
/// message carries, the ground-truth topic, or more features than `max_features` (0 = no bound;
/// counted as the first message of each topic expands its fields, before the rest is read). Each
/// stream is in stamp order (lfd_core/io/stamp_order.hpp); `warnings` gets one line per topic whose
/// stamps were out of order, duplicated or had a gap.
std::vector<lfd::Stream> readBagStreams(const DemoFiles& files,
                                        const std::vector<TopicConfig>& topics,
                                        std::vector<FeatureRole>* roles = nullptr,
                                        std::vector<std::string>* warnings = nullptr,
                                        std::size_t max_features = 0);
std::vector<lfd::Stream> readBagStreams(const std::string& path,
                                        const std::vector<TopicConfig>& topics,
                                        std::vector<FeatureRole>* roles = nullptr,
                                        std::vector<std::string>* warnings = nullptr,
                                        std::size_t max_features = 0);

/// readBagStreams + resampling at `rate` Hz (errors name the bag). Streams over `limits`
/// (features, time span, |value|) are refused before resampling (checkStreams).
DemoFeatures readBagFeatures(const DemoFiles& files, const std::vector<TopicConfig>& topics,
                             double rate, const RequestLimits& limits = RequestLimits());
DemoFeatures readBagFeatures(const std::string& path, const std::vector<TopicConfig>& topics,
                             double rate, const RequestLimits& limits = RequestLimits());

/// Every topic of the bag(s) with its type, message count and numeric fields (paths as they are
/// written in the configuration's `fields`). Throws std::runtime_error for unreadable bags.
std::string describeBag(const std::string& path);

}  // namespace lfd_segmentation
