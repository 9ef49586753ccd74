#include "lfd_segmentation/bag_features.hpp"

#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "lfd_core/io/bag_errors.hpp"
#include "lfd_core/io/input_budget.hpp"
#include "lfd_core/io/ros_message_reader.hpp"
#include "lfd_core/io/safe_paths.hpp"
#include "lfd_core/io/stamp_order.hpp"
#include "lfd_core/io/user_text.hpp"

namespace lfd_segmentation {

namespace {

namespace rosmsg = lfd::rosmsg;

std::string featureName(const std::string& topic, const std::string& field) {
  return topic + (topic.empty() || topic.back() == '/' ? "" : "/") + field;
}

// The stream MessageInstance::write copies a message's bytes into: it sizes the buffer itself,
// so the record header is parsed once per message (MessageInstance::size() would parse it again).
struct BufferStream {
  std::vector<std::uint8_t>* buffer;
  std::uint8_t* advance(std::uint32_t bytes) {
    const std::size_t used = buffer->size();
    buffer->resize(used + bytes);
    return buffer->data() + used;
  }
};

// The serialized bytes of one message, as they were recorded.
void messageBytes(const rosbag::MessageInstance& m, std::vector<std::uint8_t>& buffer) {
  buffer.clear();
  BufferStream stream{&buffer};
  m.write(stream);
}

std::string fieldList(const rosmsg::MessageSchema& schema,
                      const std::vector<std::uint8_t>& sample) {
  std::string out;
  for (const std::string& f : rosmsg::listNumericFields(schema, sample.data(), sample.size()))
    out += "\n  " + f;
  return out;
}

// A message whose bytes do not fit its declared type, already described in full.
struct MismatchedMessage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The features of a demo against limits/max_features, counted as each topic's fields are
// expanded: 10,000 columns took 1.1 GB before anything refused them.
struct FeatureCount {
  std::size_t used = 0;
  std::size_t max = 0;  // 0 = no bound
  void add(std::size_t n, const std::string& topic) {
    used += n;
    if (max > 0 && used > max)
      throw std::invalid_argument("topic " + lfd::quoted(topic) + " brings the features to " +
                                  std::to_string(used) + ", over the limit of " +
                                  std::to_string(max) + " (limits/max_features)");
  }
};

// One configured topic across the parts of a demonstration. Its features (the configured fields,
// "*" expanded) are fixed by the first message of the first part; every connection (message
// definition) on the topic gets a reader of those features.
class TopicReader {
 public:
  TopicReader(const TopicConfig& cfg, FeatureCount* count) : cfg_(cfg), count_(count) {}

  // One message of the topic, `bytes` its serialized form.
  void read(const rosbag::MessageInstance& m, const std::vector<std::uint8_t>& bytes) {
    rosmsg::FieldReader& reader = readerFor(m, bytes);
    reader.read(bytes.data(), bytes.size());
    const double stamp = reader.headerStamp();
    // A zero stamp means "not stamped" (e.g. the PR2 world model): the receive time is the clock.
    const double t = stamp != 0.0 ? stamp : m.getTime().toSec();
    for (std::size_t k = 0; k < streams_.size(); ++k) {
      if (!reader.present(k)) continue;  // this message does not carry the index or name
      streams_[k].time.push_back(t);
      streams_[k].values.push_back(reader.value(k));
    }
  }

  // The streams, once every part is read; a feature no message carried is an error.
  std::vector<lfd::Stream> takeStreams() {
    for (std::size_t k = 0; k < streams_.size(); ++k) {
      if (streams_[k].values.empty()) {
        throw std::invalid_argument(
            "topic " + cfg_.topic + " has no data for field '" + fields_[k] +
            "'; numeric fields of its first message:" + fieldList(*schema_, sample_));
      }
    }
    return std::move(streams_);
  }

 private:
  rosmsg::FieldReader& readerFor(const rosbag::MessageInstance& m,
                                 const std::vector<std::uint8_t>& bytes) {
    // getMD5Sum() refers to the connection's record: its address identifies the connection.
    if (&m.getMD5Sum() == last_connection_) return *last_reader_;
    const std::string key = m.getDataType() + " " + m.getMD5Sum();
    auto it = readers_.find(key);
    if (it == readers_.end()) {
      rosmsg::MessageSchema schema;
      try {
        schema = rosmsg::MessageSchema::parse(m.getDataType(), m.getMessageDefinition());
      } catch (const rosmsg::MessageError& e) {
        throw std::invalid_argument("topic " + cfg_.topic + ": the bag's definition of " +
                                    m.getDataType() + " cannot be parsed: " + e.what());
      }
      if (!schema_) firstMessage(schema, bytes);
      try {
        it = readers_.emplace(key, rosmsg::FieldReader(schema, fields_)).first;
      } catch (const rosmsg::UnknownField& e) {
        throw std::invalid_argument("topic " + cfg_.topic + " (" + m.getDataType() +
                                    "): " + e.what());
      }
    }
    last_connection_ = &m.getMD5Sum();
    last_reader_ = &it->second;
    return it->second;
  }

  void firstMessage(const rosmsg::MessageSchema& schema, const std::vector<std::uint8_t>& bytes) {
    schema_ = std::make_unique<rosmsg::MessageSchema>(schema);
    sample_ = bytes;
    try {
      fields_ = rosmsg::expandFields(schema, sample_.data(), sample_.size(), cfg_.fields);
    } catch (const rosmsg::UnknownField& e) {
      throw std::invalid_argument("topic " + cfg_.topic + " (" + schema.root().name +
                                  "): " + e.what());
    }
    count_->add(fields_.size(), cfg_.topic);
    for (const std::string& field : fields_) {
      lfd::Stream s;
      s.name = featureName(cfg_.topic, field);
      s.interpolation = cfg_.interpolation;
      streams_.push_back(std::move(s));
    }
  }

  const TopicConfig& cfg_;
  FeatureCount* count_;
  std::vector<std::string> fields_;
  std::vector<lfd::Stream> streams_;
  std::unique_ptr<rosmsg::MessageSchema> schema_;  // of the first message
  std::vector<std::uint8_t> sample_;               // the first message, for the error lists
  std::map<std::string, rosmsg::FieldReader> readers_;
  const std::string* last_connection_ = nullptr;
  rosmsg::FieldReader* last_reader_ = nullptr;
};

// Opens the bag through the file-access layer's descriptor: rosbag reads the file that was checked,
// never what the path names by then (a link swapped to a FIFO hung open()).
void openBag(rosbag::Bag& bag, const lfd::InputFile& file, const std::string& name) {
  try {
    bag.open(file.readPath(), rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot open bag " + lfd::quoted(name) + ": " + e.what());
  }
}

lfd::InputFile openPart(const std::string& path, const lfd::PathPolicy& policy = {}) {
  try {
    return lfd::openInputFile(path, policy);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot open bag " + lfd::quoted(path) + ": " + e.what());
  }
}

// One message of a topic into its reader; bytes that do not fit the declared type (a lying
// connection header, a truncated message: rosbag's "Buffer Overrun") are named in full.
void readMessage(const rosbag::MessageInstance& m, const std::vector<std::uint8_t>& bytes,
                 std::size_t index, const std::string& name, TopicReader& reader) {
  try {
    reader.read(m, bytes);
  } catch (const rosmsg::MessageError& e) {
    throw MismatchedMessage(lfd::mismatchedMessageError(name, m.getTopic(), m.getDataType(), index,
                                                        m.getTime().toSec(), e.what()));
  }
}

std::string topicsIn(rosbag::Bag& bag) {
  std::string available;
  rosbag::View all(bag);
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    if (c->topic != kGroundTruthTopic) available += " " + c->topic;
  }
  return available;
}

// Reads every configured topic of one bag file into the readers, a view per topic as the typed
// reader did (measured: one view over all topics saved no CPU, its connection merge costs as much
// as rereading the cached chunks).
void readPart(const lfd::InputFile& file, const std::string& path,
              const std::vector<TopicConfig>& topics, std::vector<TopicReader>& readers) {
  rosbag::Bag bag;
  openBag(bag, file, path);
  try {
    for (const TopicConfig& cfg : topics) {
      if (rosbag::View(bag, rosbag::TopicQuery(cfg.topic)).size() == 0) {
        throw std::invalid_argument("no messages on topic " + cfg.topic +
                                    " (topics in the bag:" + topicsIn(bag) + ")");
      }
    }
    std::vector<std::uint8_t> bytes;
    for (std::size_t k = 0; k < topics.size(); ++k) {
      std::size_t index = 0;
      for (const rosbag::MessageInstance& m :
           rosbag::View(bag, rosbag::TopicQuery(topics[k].topic))) {
        messageBytes(m, bytes);
        readMessage(m, bytes, index++, path, readers[k]);
      }
    }
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("bag " + lfd::quoted(path) + ": " + e.what());
  } catch (const MismatchedMessage&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read bag " + lfd::quoted(path) +
                             " (truncated or corrupt?): " + e.what());
  }
}

// Messages are stored in receive order; the shared timestamp policy puts each stream in stamp
// order (duplicates kept: resampling averages them) and reports what it found.
lfd::StampReport orderByStamp(lfd::Stream& s) {
  lfd::StampReport report;
  const std::vector<std::size_t> order =
      lfd::orderByStamp(s.time, lfd::DuplicateStamps::kKeepAll, &report);
  std::vector<double> t, v;
  t.reserve(order.size());
  v.reserve(order.size());
  for (std::size_t k : order) t.push_back(s.time[k]), v.push_back(s.values[k]);
  s.time = std::move(t);
  s.values = std::move(v);
  return report;
}

// Orders a topic's streams; one warning per topic (its fields share the messages' stamps).
void orderTopic(const std::string& topic, std::vector<lfd::Stream>& streams,
                std::vector<std::string>* warnings) {
  std::string warning;
  for (lfd::Stream& s : streams) {
    const std::string w = lfd::stampWarning(topic, orderByStamp(s));
    if (warning.empty()) warning = w;
  }
  if (warnings && !warning.empty()) warnings->push_back(warning);
}

}  // namespace

std::vector<std::string> demoParts(const std::string& path) {
  if (path.find(',') == std::string::npos || std::filesystem::exists(path)) return {path};
  std::vector<std::string> parts;
  std::stringstream in(path);
  std::string part;
  while (std::getline(in, part, ',')) {
    if (part.empty()) throw std::invalid_argument("empty bag name in " + lfd::quoted(path));
    parts.push_back(part);
  }
  return parts;
}

void checkRequestBudget(const std::vector<std::string>& entries, const RequestLimits& limits,
                        const lfd::PathPolicy& paths, const std::string& kind) {
  if (entries.size() > limits.max_bags) {
    throw std::invalid_argument(std::to_string(entries.size()) + " " + kind +
                                " paths, over the limit of " + std::to_string(limits.max_bags) +
                                " (limits/max_bags)");
  }
  std::vector<std::string> files;
  for (const std::string& entry : entries) {
    for (std::string& part : demoParts(entry)) files.push_back(std::move(part));
  }
  lfd::InputBudget budget;
  budget.what = kind + " files";
  budget.max_files = limits.max_bag_files;
  budget.max_files_key = "limits/max_bag_files";
  budget.max_total_bytes = limits.max_total_bytes;
  budget.max_total_bytes_key = "limits/max_total_bytes";
  try {
    lfd::checkInputBudget(files, budget, paths);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    // A file's own refusal (missing, FIFO, outside the roots) reads as before: "cannot open bag".
    throw std::invalid_argument(what.rfind("path ", 0) == 0 ? "cannot open " + kind + ": " + what
                                                            : what);
  }
}

DemoFiles openDemoFiles(const std::string& path, const lfd::PathPolicy& policy) {
  DemoFiles files;
  files.path = path;
  files.names = demoParts(path);
  for (const std::string& name : files.names) files.parts.push_back(openPart(name, policy));
  return files;
}

std::vector<lfd::Stream> readBagStreams(const std::string& path,
                                        const std::vector<TopicConfig>& topics,
                                        std::vector<FeatureRole>* roles,
                                        std::vector<std::string>* warnings,
                                        std::size_t max_features) {
  return readBagStreams(openDemoFiles(path), topics, roles, warnings, max_features);
}

std::vector<lfd::Stream> readBagStreams(const DemoFiles& files,
                                        const std::vector<TopicConfig>& topics,
                                        std::vector<FeatureRole>* roles,
                                        std::vector<std::string>* warnings,
                                        std::size_t max_features) {
  const std::string& path = files.path;
  if (topics.empty()) throw std::invalid_argument("no topics configured for the features");
  for (const TopicConfig& cfg : topics) {
    if (cfg.topic == kGroundTruthTopic) {
      throw std::invalid_argument("bag " + lfd::quoted(path) + ": " + kGroundTruthTopic +
                                  " is ground truth and is never read by the segmenter");
    }
  }
  FeatureCount count{0, max_features};
  std::vector<TopicReader> readers;
  readers.reserve(topics.size());
  for (const TopicConfig& cfg : topics) readers.emplace_back(cfg, &count);
  for (std::size_t k = 0; k < files.parts.size(); ++k)
    readPart(files.parts[k], files.names[k], topics, readers);
  std::vector<lfd::Stream> streams;
  if (roles) roles->clear();
  for (std::size_t k = 0; k < topics.size(); ++k) {
    std::vector<lfd::Stream> topic_streams;
    try {
      topic_streams = readers[k].takeStreams();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("bag " + lfd::quoted(path) + ": " + e.what());
    }
    orderTopic(topics[k].topic, topic_streams, warnings);
    if (roles) roles->insert(roles->end(), topic_streams.size(), topics[k].role);
    for (lfd::Stream& s : topic_streams) streams.push_back(std::move(s));
  }
  return streams;
}

DemoFeatures readBagFeatures(const std::string& path, const std::vector<TopicConfig>& topics,
                             double rate, const RequestLimits& limits) {
  return readBagFeatures(openDemoFiles(path), topics, rate, limits);
}

DemoFeatures readBagFeatures(const DemoFiles& files, const std::vector<TopicConfig>& topics,
                             double rate, const RequestLimits& limits) {
  const std::string& path = files.path;
  std::vector<FeatureRole> roles;
  std::vector<std::string> warnings;
  const std::vector<lfd::Stream> streams =
      readBagStreams(files, topics, &roles, &warnings, limits.max_features);
  checkStreams(streams, path, limits);
  double start = -INFINITY, end = INFINITY;  // the span resample() keeps: where all streams overlap
  for (const lfd::Stream& s : streams) {
    if (s.time.empty()) continue;
    start = std::max(start, s.time.front());
    end = std::min(end, s.time.back());
  }
  if (end > start && (end - start) * rate + 1 > static_cast<double>(limits.max_samples_per_demo)) {
    throw std::invalid_argument("bag " + lfd::quoted(path) + ": " + std::to_string(end - start) +
                                " s at " + std::to_string(rate) + " Hz is over the limit of " +
                                std::to_string(limits.max_samples_per_demo) +
                                " samples per demo (limits/max_samples_per_demo)");
  }
  DemoFeatures demo;
  demo.source = path;
  for (const std::string& w : warnings)
    demo.warnings.push_back("bag " + lfd::quoted(path) + ": " + w);
  try {
    demo.matrix = lfd::resample(streams, rate);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("bag " + lfd::quoted(path) + ": " + e.what());
  }
  for (std::size_t k = 0; k < streams.size(); ++k) {
    if (roles[k] == FeatureRole::kSensor) demo.sensor_features.push_back(streams[k].name);
    if (roles[k] == FeatureRole::kState) demo.state_features.push_back(streams[k].name);
    if (roles[k] == FeatureRole::kContext) demo.context_features.push_back(streams[k].name);
  }
  return demo;
}

std::string describeBag(const std::string& path) {
  std::ostringstream out;
  for (const std::string& part : demoParts(path)) {
    rosbag::Bag bag;
    const lfd::InputFile file = openPart(part);
    openBag(bag, file, part);
    out << part << "\n";
    try {
      rosbag::View all(bag);
      std::map<std::string, const rosbag::ConnectionInfo*> topics;
      for (const rosbag::ConnectionInfo* c : all.getConnections()) topics.emplace(c->topic, c);
      for (const auto& [topic, connection] : topics) {
        rosbag::View view(bag, rosbag::TopicQuery(topic));
        out << topic << " (" << connection->datatype << ", " << view.size() << " messages)";
        if (topic == kGroundTruthTopic || view.size() == 0) {
          out << (view.size() ? ": ground truth, never read by the segmenter\n" : "\n");
          continue;
        }
        std::vector<std::uint8_t> sample;
        const rosbag::MessageInstance first = *view.begin();
        messageBytes(first, sample);
        const rosmsg::MessageSchema schema =
            rosmsg::MessageSchema::parse(connection->datatype, connection->msg_def);
        try {
          out << fieldList(schema, sample) << "\n";
        } catch (const rosmsg::MessageError& e) {
          throw MismatchedMessage(lfd::mismatchedMessageError(part, topic, connection->datatype, 0,
                                                              first.getTime().toSec(), e.what()));
        }
      }
    } catch (const MismatchedMessage&) {
      throw;
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot read bag " + lfd::quoted(part) + ": " + e.what());
    }
  }
  return out.str();
}

}  // namespace lfd_segmentation
