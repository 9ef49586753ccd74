#include "lfd_sim_bridge/demo_metadata.hpp"

#include <cstdio>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace lfd_sim_bridge {
namespace demo {

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string poseJson(const Pose& p) {
  std::ostringstream s;
  s << std::setprecision(9) << "{\"position\": [" << p.position.x() << ", " << p.position.y()
    << ", " << p.position.z() << "], \"orientation\": [" << p.orientation.w() << ", "
    << p.orientation.x() << ", " << p.orientation.y() << ", " << p.orientation.z() << "]}";
  return s.str();
}

std::string metadataJson(const DemoMetadata& m) {
  if (!m.task || !m.scene || !m.configuration)
    throw std::invalid_argument("metadataJson needs the task, the scene and the configuration");
  const task::TaskDefinition& t = *m.task;
  const task::Configuration& c = *m.configuration;
  std::ostringstream s;
  s << std::setprecision(9);
  s << "{\"task\": " << jsonString(t.name) << ", \"frame\": \"world\", \"scene\": {\"frame\": "
    << "\"world\", \"objects\": {";
  for (size_t i = 0; i < t.objects.size(); ++i)
    s << (i ? ", " : "") << jsonString(t.objects[i]) << ": "
      << poseJson(c.objects.at(t.objects[i]));
  s << "}, \"goal\": " << poseJson(c.goal) << ", \"joints\": {";
  const std::vector<std::string> joints = t.joints(*m.scene);
  for (size_t i = 0; i < joints.size(); ++i) {
    const auto q = c.joints.find(joints[i]);
    s << (i ? ", " : "") << jsonString(joints[i]) << ": "
      << (q == c.joints.end() ? 0.0 : q->second);
  }
  s << "}}, \"phases\": [";
  for (size_t i = 0; i < t.phases.size(); ++i) s << (i ? ", " : "") << jsonString(t.phases[i].name);
  s << "], \"windows\": [";
  bool first = true;
  for (const task::PhaseSpec& p : t.phases)
    if (p.window) {
      s << (first ? "" : ", ") << jsonString(p.name);
      first = false;
    }
  const std::string object = t.objects.empty() ? "" : t.objects.front();
  s << "], \"object\": " << jsonString(object);
  if (!object.empty()) s << ", \"object_start\": " << poseJson(c.objects.at(object));
  s << ", \"goal\": " << poseJson(c.goal) << ", \"table_top\": " << m.scene->table_top
    << ", \"seed\": " << m.seed << ", \"speed\": " << m.speed << ", \"aim\": {";
  first = true;
  for (const auto& [name, offset] : m.aim_offsets) {
    s << (first ? "" : ", ") << jsonString(name) << ": {\"offset\": [" << offset.first.x() << ", "
      << offset.first.y() << ", " << offset.first.z() << "], \"yaw\": " << offset.second << "}";
    first = false;
  }
  s << "}, \"tremor_rms\": " << m.tremor_rms << ", \"planned_duration\": " << m.planned_duration
    << ", \"task_file\": " << jsonString(t.path) << "}";
  return s.str();
}

}  // namespace demo
}  // namespace lfd_sim_bridge
