#include "lfd_sim_bridge/task_file.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>
#include <lfd_core/io/safe_paths.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace lfd_sim_bridge {
namespace task {
namespace {

const char* const kModes[] = {"sim", "teleop"};

// The YAML spec's printable characters (c-printable), the only ones a YAML stream may hold.
// yaml-cpp does not check them; PyYAML (lfd_tools.tasks) refuses the others, so both refuse.
bool printable(std::uint32_t c) {
  return c == 0x09 || c == 0x0A || c == 0x0D || (c >= 0x20 && c <= 0x7E) || c == 0x85 ||
         (c >= 0xA0 && c <= 0xD7FF) || (c >= 0xE000 && c <= 0xFFFD) ||
         (c >= 0x10000 && c <= 0x10FFFF);
}

// "" when `bytes` are UTF-8 text of printable characters, else what is wrong and where.
std::string textProblem(const std::string& bytes) {
  std::size_t line = 1;
  for (std::size_t i = 0; i < bytes.size();) {
    const auto b = static_cast<unsigned char>(bytes[i]);
    const int extra = b < 0x80           ? 0
                      : (b >> 5) == 0x6  ? 1
                      : (b >> 4) == 0xE  ? 2
                      : (b >> 3) == 0x1E ? 3
                                         : -1;
    if (extra < 0 || i + extra >= bytes.size())  // not a lead byte, or cut off
      return "line " + std::to_string(line) + " is not UTF-8 text";
    std::uint32_t c = extra == 0 ? b : b & (0x3F >> extra);
    for (int k = 1; k <= extra; ++k) {
      const auto cont = static_cast<unsigned char>(bytes[i + k]);
      if ((cont >> 6) != 0x2) return "line " + std::to_string(line) + " is not UTF-8 text";
      c = (c << 6) | (cont & 0x3F);
    }
    static const std::uint32_t kLeast[] = {0, 0x80, 0x800, 0x10000};  // overlong forms
    if (c < kLeast[extra] || !printable(c))
      return "line " + std::to_string(line) + " holds a character that is not printable text";
    if (c == '\n') ++line;
    i += 1 + extra;
  }
  return "";
}

std::string tooDeep(int max_depth) {
  if (max_depth <= 0) return "nested too deep";
  return "nested deeper than " + std::to_string(max_depth) +
         " levels (task_limits/max_nesting_depth of the scene file)";
}

std::string lineOf(const YAML::Node& n) {
  return "line " + std::to_string(n.Mark().line + 1);
}

// "" when the tree nests at most `max_depth` collections, has no key twice in a mapping, no key
// that is not a plain value and no tag; else what is wrong and where. Iterative: the depth is not
// known yet, so no recursion may depend on it.
std::string treeProblem(const YAML::Node& root, int max_depth) {
  std::vector<std::pair<YAML::Node, int>> todo{{root, root.IsScalar() ? 0 : 1}};
  while (!todo.empty()) {
    const auto [n, depth] = todo.back();
    todo.pop_back();
    if (n.Tag() != "?" && n.Tag() != "!" && !n.Tag().empty())
      return lineOf(n) + ": tag '" + n.Tag() + "' (task files use none)";
    if (!n.IsMap() && !n.IsSequence()) continue;
    if (depth > max_depth) return lineOf(n) + ": " + tooDeep(max_depth);
    std::set<std::string> keys;
    for (const auto& child : n) {
      if (n.IsSequence()) {
        todo.emplace_back(child, depth + 1);
        continue;
      }
      if (!child.first.IsScalar()) return lineOf(child.first) + ": a key must be a plain value";
      if (!keys.insert(child.first.Scalar()).second)
        return lineOf(child.first) + ": key '" + child.first.Scalar() + "' given twice";
      todo.emplace_back(child.first, depth + 1);
      todo.emplace_back(child.second, depth + 1);
    }
  }
  return "";
}

// Reads one file's nodes; every error names the file and the key.
class Reader {
 public:
  Reader(std::string kind, std::string path) : kind_(std::move(kind)), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error(kind_ + " file '" + path_ + "': " + key + ": " + what);
  }

  // The file's tree, its text and its shape checked (max_depth > 0: a task file's bounds).
  YAML::Node load(int max_depth = 0) const {
    YAML::Node root;
    try {
      root = YAML::Load(text());
    } catch (
        const YAML::DeepRecursion&) {  // yaml-cpp's own bound (500 levels), far beyond any file
      unreadable(tooDeep(max_depth));
    } catch (const YAML::Exception& e) {
      unreadable(e.what());
    }
    if (max_depth > 0) {
      const std::string problem = treeProblem(root, max_depth);
      if (!problem.empty()) unreadable(problem);
    }
    if (!root.IsMap()) fail("(top level)", "expected a mapping");
    return root;
  }

  [[noreturn]] void unreadable(const std::string& why) const {
    throw std::runtime_error(kind_ + " file '" + path_ + "' cannot be read: " + why);
  }

  double number(const YAML::Node& n, const std::string& key) const {
    if (!n || !n.IsScalar()) fail(key, "expected a number");
    try {
      const double v = n.as<double>();
      if (!std::isfinite(v)) fail(key, "is not finite");
      return v;
    } catch (const YAML::Exception&) {
      fail(key, "'" + n.Scalar() + "' is not a number");
    }
  }

  double positive(const YAML::Node& n, const std::string& key) const {
    const double v = number(n, key);
    if (!(v > 0.0)) fail(key, "must be > 0");
    return v;
  }

  // A time of the file: 0 to `max` s (the scene's task_limits/max_step_seconds).
  double seconds(const YAML::Node& n, const std::string& key, double max) const {
    const double v = number(n, key);
    if (v < 0.0) fail(key, "must be >= 0 s");
    atMost(v, key, max);
    return v;
  }

  void atMost(double seconds, const std::string& key, double max) const {
    if (seconds > max)
      fail(key, std::to_string(seconds) + " s is over " + std::to_string(max) +
                    " s (task_limits/max_step_seconds of the scene file)");
  }

  // A whole number from `lo` to the largest int.
  int whole(const YAML::Node& n, const std::string& key, int lo) const {
    const double v = number(n, key);
    if (v < lo || v > std::numeric_limits<int>::max() || v != std::floor(v))
      fail(key, "expected a whole number >= " + std::to_string(lo));
    return static_cast<int>(v);
  }

  // The file's bytes, read once through the file-access layer (a link swapped to a FIFO cannot
  // hang the read), checked to be printable UTF-8 text.
  std::string text() const {
    std::ostringstream bytes;
    try {
      const lfd::InputFile file = lfd::openInputFile(path_);
      std::ifstream in(file.readPath(), std::ios::binary);
      bytes << in.rdbuf();
    } catch (const std::invalid_argument& e) {  // the file-access layer's refusal
      unreadable(e.what());
    }
    const std::string problem = textProblem(bytes.str());
    if (!problem.empty()) unreadable(problem);
    return bytes.str();
  }

  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n || !n.IsScalar() || n.Scalar().empty()) fail(key, "expected a name");
    return n.Scalar();
  }

  bool flag(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(key, "expected true or false");
    }
  }

  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& key) const {
    if (!n || !n.IsSequence() || n.size() != 3) fail(key, "expected [x, y, z]");
    return {number(n[0], key + "[0]"), number(n[1], key + "[1]"), number(n[2], key + "[2]")};
  }

  // [x, y, z], [x, y, z, yaw] or {position: [x, y, z], orientation: [w, x, y, z] | yaw: a}
  Pose pose(const YAML::Node& n, const std::string& key) const {
    Pose p;
    if (n && n.IsSequence() && (n.size() == 3 || n.size() == 4)) {
      for (int i = 0; i < 3; ++i) p.position[i] = number(n[i], key + "[" + std::to_string(i) + "]");
      if (n.size() == 4) p.orientation = yawRotation(number(n[3], key + "[3]"));
      return p;
    }
    if (!n || !n.IsMap() || !n["position"])
      fail(key, "expected a pose [x, y, z, yaw] or {position, orientation}");
    p.position = vec3(n["position"], key + ".position");
    if (const YAML::Node q = n["orientation"]) {
      if (!q.IsSequence() || q.size() != 4) fail(key + ".orientation", "expected [w, x, y, z]");
      Eigen::Quaterniond o(number(q[0], key + ".orientation"), number(q[1], key + ".orientation"),
                           number(q[2], key + ".orientation"), number(q[3], key + ".orientation"));
      if (o.norm() < 1e-9) fail(key + ".orientation", "is a zero quaternion");
      p.orientation = o.normalized();
    } else if (n["yaw"]) {
      p.orientation = yawRotation(number(n["yaw"], key + ".yaw"));
    }
    return p;
  }

  // Fails on a key of `n` outside `known` (a typo would otherwise be silently ignored).
  void onlyKeys(const YAML::Node& n, const std::string& key,
                const std::set<std::string>& known) const {
    for (const auto& kv : n) {
      const std::string k = kv.first.Scalar();
      if (!known.count(k)) {
        std::string list;
        for (const std::string& s : known) list += (list.empty() ? "" : ", ") + s;
        fail(key, "unknown key '" + k + "' (expected one of " + list + ")");
      }
    }
  }

  static Eigen::Quaterniond yawRotation(double yaw) {
    return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  }

 private:
  std::string kind_, path_;
};

SceneObject readSceneObject(const Reader& r, const std::string& name, const YAML::Node& n) {
  const std::string key = "objects." + name;
  if (!n.IsMap()) r.fail(key, "expected a mapping");
  r.onlyKeys(n, key, {"half_size", "park", "fixed", "frames", "joints"});
  SceneObject o;
  o.name = name;
  o.half_size = r.vec3(n["half_size"], key + ".half_size");
  o.park = r.pose(n["park"], key + ".park");
  if (n["fixed"]) o.fixed = r.flag(n["fixed"], key + ".fixed");
  for (const auto& j : n["joints"]) {
    const std::string jkey = key + ".joints." + j.first.Scalar();
    SceneJoint joint;
    joint.axis = r.vec3(j.second["axis"], jkey + ".axis");
    if (joint.axis.norm() < 1e-9) r.fail(jkey + ".axis", "is zero");
    joint.axis.normalize();
    const YAML::Node range = j.second["range"];
    if (!range.IsSequence() || range.size() != 2)
      r.fail(jkey + ".range", "expected [lower, upper]");
    joint.lower = r.number(range[0], jkey + ".range");
    joint.upper = r.number(range[1], jkey + ".range");
    o.joints[j.first.Scalar()] = joint;
  }
  for (const auto& f : n["frames"]) {
    const std::string fkey = key + ".frames." + f.first.Scalar();
    ObjectFrame frame;
    if (f.second.IsMap() && f.second["pose"]) {
      r.onlyKeys(f.second, fkey, {"pose", "joint", "body"});
      frame.pose = r.pose(f.second["pose"], fkey + ".pose");
      if (f.second["joint"]) frame.joint = r.text(f.second["joint"], fkey + ".joint");
      if (f.second["body"]) frame.body = r.text(f.second["body"], fkey + ".body");
      if (!frame.joint.empty() && !o.joints.count(frame.joint))
        r.fail(fkey + ".joint", "'" + frame.joint + "' is not a joint of " + name);
    } else {
      frame.pose = r.pose(f.second, fkey);
    }
    o.frames[f.first.Scalar()] = frame;
  }
  return o;
}

// ---- task file ------------------------------------------------------------------------------

class TaskReader {
 public:
  TaskReader(const std::string& path, const Scene& scene) : r_("task", path), scene_(scene) {}

  TaskDefinition read() {
    const YAML::Node root = r_.load(scene_.task_limits.max_nesting_depth);
    r_.onlyKeys(root, "(top level)",
                {"description", "objects", "goal", "gripper_at_start", "variation",
                 "teleop_placement", "frames", "phases", "success", "configurations", "unseen"});
    readObjects(root["objects"]);
    if (const YAML::Node g = root["gripper_at_start"]) {
      const std::string s = r_.text(g, "gripper_at_start");
      if (s != "open" && s != "closed") r_.fail("gripper_at_start", "expected open or closed");
      task_.gripper_closed_at_start = s == "closed";
    }
    readVariation(root["variation"], root["teleop_placement"]);
    readFrames(root["frames"]);
    readPhases(root["phases"]);
    if (!root["success"]) r_.fail("success", "missing: the physical success criterion");
    for (const char* mode : kModes) {
      task_.configurations[mode] = readConfigurations(root["configurations"][mode],
                                                      std::string("configurations.") + mode, true);
      if (root["unseen"])
        task_.unseen[mode] =
            readConfigurations(root["unseen"][mode], std::string("unseen.") + mode, false);
    }
    checkIds();
    return task_;
  }

 private:
  TaskDefinition task_;  // what read() fills and returns

  void readObjects(const YAML::Node& n) {
    if (!n || !n.IsSequence()) r_.fail("objects", "expected a list of scene objects ([] for none)");
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string name = r_.text(n[i], "objects[" + std::to_string(i) + "]");
      if (!scene_.find(name))
        r_.fail("objects[" + std::to_string(i) + "]",
                "'" + name + "' is not an object of the scene file '" + scene_.path + "'");
      task_.objects.push_back(name);
    }
  }

  bool isObject(const std::string& name) const {
    return std::find(task_.objects.begin(), task_.objects.end(), name) != task_.objects.end();
  }

  // An object of the task or one of its frames ("drawer.handle").
  bool isObjectOrPart(const std::string& name) const {
    if (isObject(name)) return true;
    const size_t dot = name.find('.');
    if (dot == std::string::npos || !isObject(name.substr(0, dot))) return false;
    return scene_.find(name.substr(0, dot))->frames.count(name.substr(dot + 1)) > 0;
  }

  bool isFrame(const std::string& name) const {
    if (isBuiltinFrame(name) || isObjectOrPart(name)) return true;
    return std::any_of(task_.frames.begin(), task_.frames.end(),
                       [&](const auto& f) { return f.first == name; });
  }

  void needFrame(const std::string& name, const std::string& key) const {
    if (!isFrame(name))
      r_.fail(key, "unknown frame '" + name +
                       "' (an object of the task, object.frame, goal, start, base, tcp or a frame "
                       "defined under frames: before it)");
  }

  // {object: {x, y, z, yaw}}: uniform +- ranges in the object's axes (m, rad).
  std::map<std::string, Jitter> readJitters(const YAML::Node& n, const std::string& section) const {
    std::map<std::string, Jitter> out;
    if (n && !n.IsMap()) r_.fail(section, "expected {object: {x, y, z, yaw}}");
    for (const auto& kv : n) {
      const std::string name = kv.first.Scalar(), key = section + "." + name;
      if (!isObject(name)) r_.fail(key, "'" + name + "' is not an object of the task");
      r_.onlyKeys(kv.second, key, {"x", "y", "z", "yaw"});
      Jitter j;
      const char* axes[] = {"x", "y", "z"};
      for (int i = 0; i < 3; ++i)
        if (kv.second[axes[i]]) j.position[i] = r_.number(kv.second[axes[i]], key + "." + axes[i]);
      if (kv.second["yaw"]) j.yaw = r_.number(kv.second["yaw"], key + ".yaw");
      out[name] = j;
    }
    return out;
  }

  void readVariation(const YAML::Node& variation, const YAML::Node& placement) {
    task_.variation = readJitters(variation, "variation");
    task_.teleop_placement = readJitters(placement, "teleop_placement");
  }

  PoseSpec poseSpec(const YAML::Node& n, const std::string& key) const {
    if (!n || !n.IsMap()) r_.fail(key, "expected {frame: NAME, position: [x, y, z], ...}");
    r_.onlyKeys(n, key, {"frame", "axes", "position", "yaw", "symmetry"});
    PoseSpec s;
    s.frame = r_.text(n["frame"], key + ".frame");
    needFrame(s.frame, key + ".frame");
    if (n["axes"]) {
      s.axes = r_.text(n["axes"], key + ".axes");
      needFrame(s.axes, key + ".axes");
    }
    if (n["position"]) s.position = r_.vec3(n["position"], key + ".position");
    if (n["yaw"]) s.yaw = r_.number(n["yaw"], key + ".yaw");
    if (n["symmetry"]) s.symmetry = r_.whole(n["symmetry"], key + ".symmetry", 1);
    return s;
  }

  // A task frame is fixed when the demo starts: it cannot follow the moving TCP.
  void needFixedFrame(const std::string& name, const std::string& key) const {
    needFrame(name, key);
    if (name == "tcp") r_.fail(key, "a frame is fixed when the demo starts: it cannot use tcp");
  }

  void readFrames(const YAML::Node& n) {
    for (const auto& kv : n) {
      const std::string name = kv.first.Scalar(), key = "frames." + name;
      if (isBuiltinFrame(name) || isObjectOrPart(name) || name.find('.') != std::string::npos)
        r_.fail(key, "'" + name + "' is already a frame (or has a '.')");
      FrameSpec f;
      f.where = key;
      const YAML::Node v = kv.second;
      if (v["heading"]) {
        r_.onlyKeys(v, key, {"heading"});
        r_.onlyKeys(v["heading"], key + ".heading", {"from", "to"});
        f.kind = FrameSpec::Kind::kHeading;
        f.from = r_.text(v["heading"]["from"], key + ".heading.from");
        f.to = r_.text(v["heading"]["to"], key + ".heading.to");
        needFixedFrame(f.from, key + ".heading.from");
        needFixedFrame(f.to, key + ".heading.to");
      } else if (v["touch"]) {
        r_.onlyKeys(v, key, {"touch", "along"});
        f.kind = FrameSpec::Kind::kTouch;
        f.object = r_.text(v["touch"], key + ".touch");
        if (!isObject(f.object))
          r_.fail(key + ".touch", "'" + f.object + "' is not an object of the task");
        f.along = r_.text(v["along"], key + ".along");
        needFixedFrame(f.along, key + ".along");
      } else {
        f.kind = FrameSpec::Kind::kRelative;
        f.relative = poseSpec(v, key);
        needFixedFrame(f.relative.frame, key + ".frame");
        if (!f.relative.axes.empty()) needFixedFrame(f.relative.axes, key + ".axes");
      }
      task_.frames.emplace_back(name, f);
    }
  }

  Contact contact(const YAML::Node& n, const std::string& key, Contact if_true) const {
    if (n.IsScalar() && (n.Scalar() == "any" || n.Scalar() == "both"))
      return n.Scalar() == "any" ? Contact::kAny : Contact::kBoth;
    return r_.flag(n, key) ? if_true : Contact::kNone;
  }

  Step readStep(const YAML::Node& n, const std::string& key) const {
    if (!n.IsMap()) r_.fail(key, "expected a mapping with one primitive");
    static const std::set<std::string> kPrimitives = {"move",    "carry", "push",   "gripper",
                                                      "release", "hold",  "retreat"};
    std::vector<std::string> found;
    for (const auto& kv : n)
      if (kPrimitives.count(kv.first.Scalar())) found.push_back(kv.first.Scalar());
    if (found.size() != 1)
      r_.fail(key,
              "expected exactly one primitive of move, carry, push, gripper, release, hold, "
              "retreat");
    const std::string p = found.front();
    Step s;
    s.where = key;
    s.label = n["label"] ? r_.text(n["label"], key + ".label") : p;
    if (p == "hold" || p == "release") {
      r_.onlyKeys(n, key, {p, "label"});
      s.kind = p == "hold" ? StepKind::kHold : StepKind::kGripper;
      s.open = true;
      s.duration = r_.seconds(n[p], key + "." + p, maxSeconds());
      return s;
    }
    if (p == "gripper") {
      r_.onlyKeys(n, key, {"gripper", "duration", "label", "until_contact", "settle"});
      const std::string what = r_.text(n["gripper"], key + ".gripper");
      if (what != "open" && what != "close") r_.fail(key + ".gripper", "expected open or close");
      s.kind = StepKind::kGripper;
      s.open = what == "open";
      if (n["until_contact"])
        s.until_contact = contact(n["until_contact"], key + ".until_contact", Contact::kBoth);
      if (s.open && s.until_contact != Contact::kNone)
        r_.fail(key + ".until_contact", "only a close waits for contact");
    } else if (p == "retreat") {
      r_.onlyKeys(n, key, {"retreat", "axes", "duration", "label"});
      s.kind = StepKind::kMove;
      s.target.frame = "tcp";
      s.target.position = r_.vec3(n["retreat"], key + ".retreat");
      if (n["axes"]) {
        s.target.axes = r_.text(n["axes"], key + ".axes");
        needFrame(s.target.axes, key + ".axes");
      }
    } else if (p == "move") {
      r_.onlyKeys(n, key, {"move", "duration", "label", "until_contact", "settle"});
      s.kind = StepKind::kMove;
      s.target = poseSpec(n["move"], key + ".move");
      if (n["until_contact"])
        s.until_contact = contact(n["until_contact"], key + ".until_contact", Contact::kAny);
    } else {  // carry, push
      r_.onlyKeys(n, key, {p, "to", "duration", "label"});
      s.kind = p == "carry" ? StepKind::kCarry : StepKind::kPush;
      s.held = r_.text(n[p], key + "." + p);
      if (!isObjectOrPart(s.held))
        r_.fail(key + "." + p, "'" + s.held + "' is not an object (or object.frame) of the task");
      s.target = poseSpec(n["to"], key + ".to");
    }
    s.duration = r_.positive(n["duration"], key + ".duration");
    r_.atMost(s.duration, key + ".duration", maxSeconds());
    if (n["settle"]) s.settle = r_.seconds(n["settle"], key + ".settle", maxSeconds());
    return s;
  }

  double maxSeconds() const { return scene_.task_limits.max_step_seconds; }

  void readPhases(const YAML::Node& n) {
    if (!n || !n.IsSequence() || n.size() == 0) r_.fail("phases", "expected a non-empty list");
    bool closed = false;  // a carry needs the hand to have closed on something before
    std::set<std::string> names;
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string key = "phases[" + std::to_string(i) + "]";
      r_.onlyKeys(n[i], key, {"name", "window", "steps"});
      PhaseSpec phase;
      phase.name = r_.text(n[i]["name"], key + ".name");
      if (!names.insert(phase.name).second) r_.fail(key + ".name", "'" + phase.name + "' repeats");
      if (n[i]["window"]) phase.window = r_.flag(n[i]["window"], key + ".window");
      const YAML::Node steps = n[i]["steps"];
      if (!steps || !steps.IsSequence() || steps.size() == 0)
        r_.fail(key + ".steps", "expected a non-empty list of primitives");
      for (size_t k = 0; k < steps.size(); ++k) {
        const Step s = readStep(steps[k], key + ".steps[" + std::to_string(k) + "]");
        if (s.until_contact != Contact::kNone && k + 1 != steps.size())
          r_.fail(s.where + ".until_contact",
                  "a step that waits for contact ends its phase: make it the phase's last step");
        if (s.kind == StepKind::kCarry && !closed)
          r_.fail(s.where, "carry before any gripper close: nothing is held");
        if (s.kind == StepKind::kGripper) closed = !s.open;
        phase.steps.push_back(s);
      }
      task_.phases.push_back(phase);
    }
    const auto& ph = task_.phases;
    if (ph.front().window || ph.back().window)
      r_.fail("phases", "the first and the last phase are skills, not windows");
    for (size_t i = 1; i < ph.size(); ++i)
      if (ph[i].window && ph[i - 1].window)
        r_.fail("phases[" + std::to_string(i) + "].window", "two windows in a row");
  }

  std::vector<Configuration> readConfigurations(const YAML::Node& n, const std::string& key,
                                                bool required) const {
    if (!n) {
      if (required) r_.fail(key, "missing: a list of configurations");
      return {};
    }
    if (!n.IsSequence() || (required && n.size() == 0)) r_.fail(key, "expected a non-empty list");
    const std::vector<std::string> joints = task_.joints(scene_);
    std::vector<Configuration> out;
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string ckey = key + "[" + std::to_string(i) + "]";
      const YAML::Node e = n[i];
      if (!e.IsMap()) r_.fail(ckey, "expected a mapping");
      Configuration c;
      c.id = r_.whole(e["id"], ckey + ".id", 0);
      for (const std::string& object : task_.objects)
        c.objects[object] = r_.pose(e[object], ckey + "." + object);
      c.goal = r_.pose(e["goal"], ckey + ".goal");
      for (const auto& kv : e) {
        const std::string k = kv.first.Scalar();
        if (k != "id" && k != "goal" && k != "joints" && !isObject(k))
          r_.fail(ckey,
                  "unknown key '" + k + "' (expected id, goal, joints and the task's objects)");
      }
      for (const auto& kv : e["joints"]) {
        const std::string j = kv.first.Scalar();
        if (std::find(joints.begin(), joints.end(), j) == joints.end())
          r_.fail(ckey + ".joints." + j, "not a joint of the task's objects");
        c.joints[j] = r_.number(kv.second, ckey + ".joints." + j);
      }
      out.push_back(c);
    }
    return out;
  }

  void checkIds() {
    for (const char* mode : kModes) {
      std::set<int> ids;
      for (const auto* list : {&task_.configurations[mode], &task_.unseen[mode]})
        for (const Configuration& c : *list)
          if (!ids.insert(c.id).second)
            r_.fail(std::string("configurations/unseen.") + mode,
                    "id " + std::to_string(c.id) + " repeats");
    }
  }

  Reader r_;
  const Scene& scene_;
};

}  // namespace

const SceneObject* Scene::find(const std::string& name) const {
  for (const SceneObject& o : objects)
    if (o.name == name) return &o;
  return nullptr;
}

namespace {

Scene readScene(const std::string& path) {
  const Reader r("scene", path);
  const YAML::Node root = r.load();
  Scene s;
  s.path = path;
  s.table_top = r.number(root["table_top"], "table_top");
  s.base_in_world = r.vec3(root["base_link_in_world"], "base_link_in_world");
  const YAML::Node q = root["tool_orientation"];
  if (!q || !q.IsSequence() || q.size() != 4) r.fail("tool_orientation", "expected [w, x, y, z]");
  s.tool_orientation =
      Eigen::Quaterniond(r.number(q[0], "tool_orientation"), r.number(q[1], "tool_orientation"),
                         r.number(q[2], "tool_orientation"), r.number(q[3], "tool_orientation"));
  if (s.tool_orientation.norm() < 1e-9) r.fail("tool_orientation", "is a zero quaternion");
  s.tool_orientation.normalize();
  const YAML::Node objects = root["objects"];
  if (!objects || !objects.IsMap()) r.fail("objects", "expected a mapping of objects");
  for (const auto& kv : objects)
    s.objects.push_back(readSceneObject(r, kv.first.Scalar(), kv.second));
  const YAML::Node limits = root["task_limits"];
  if (!limits || !limits.IsMap())
    r.fail("task_limits",
           "expected {max_step_seconds, max_nesting_depth}: every task file's bounds");
  s.task_limits.max_step_seconds =
      r.positive(limits["max_step_seconds"], "task_limits.max_step_seconds");
  s.task_limits.max_nesting_depth =
      r.whole(limits["max_nesting_depth"], "task_limits.max_nesting_depth", 1);
  return s;
}

}  // namespace

Scene loadScene(const std::string& path) {
  try {
    return readScene(path);
  } catch (const YAML::Exception& e) {  // a node of another kind than the reader asked for
    throw std::runtime_error("scene file '" + path + "' is malformed: " + e.what());
  }
}

std::vector<std::string> TaskDefinition::joints(const Scene& scene) const {
  std::vector<std::string> out;
  for (const std::string& name : objects)
    if (const SceneObject* o = scene.find(name))
      for (const auto& kv : o->joints) out.push_back(kv.first);
  return out;
}

TaskDefinition loadTask(const std::string& path, const Scene& scene) {
  TaskReader reader(path, scene);
  TaskDefinition t;
  try {
    t = reader.read();
  } catch (const YAML::Exception& e) {  // a node of another kind than the reader asked for
    throw std::runtime_error("task file '" + path + "' is malformed: " + e.what());
  }
  t.path = path;
  std::string stem = path.substr(path.find_last_of('/') + 1);
  if (stem.size() > 5 && stem.substr(stem.size() - 5) == ".yaml") stem.resize(stem.size() - 5);
  t.name = stem;
  return t;
}

std::string taskFilePath(const std::string& tasks_dir, const std::string& name) {
  return tasks_dir + "/" + name + ".yaml";
}

bool isBuiltinFrame(const std::string& name) {
  return name == "goal" || name == "start" || name == "base" || name == "tcp";
}

}  // namespace task
}  // namespace lfd_sim_bridge
