#include "lfd_dmp/skill_library.hpp"

#include "json_fields.hpp"
#include "lfd_dmp/signature_json.hpp"

#include <lfd_core/io/safe_paths.hpp>
#include <lfd_core/io/user_text.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

using nlohmann::json;
using namespace json_fields;

json quaternionJson(const Eigen::Quaterniond& q) {
  return json::array({q.w(), q.x(), q.y(), q.z()});
}

/// Weights N x D as D arrays of N numbers (one array per dimension reads naturally).
json weightsJson(const Eigen::MatrixXd& w) {
  json out = json::array();
  for (Eigen::Index d = 0; d < w.cols(); ++d) out.push_back(vectorJson(w.col(d)));
  return out;
}

// Finite is not enough: a rollout of a huge number overflows to inf/NaN downstream (IK, the
// bridge). Learned forcing weights of real demos stay below 1e4 (scaled accelerations); 1e9 leaves
// room for any fit and still keeps every rollout finite. Positions beyond 1 km are no workcell's.
constexpr double kMaxWeightMagnitude = 1e9;
constexpr double kMaxPositionMagnitude = 1e3;  // m

template <class Matrix>
Matrix bounded(Matrix values, double limit, const std::string& where, const char* what) {
  for (Eigen::Index k = 0; k < values.size(); ++k) {
    if (std::abs(values.data()[k]) > limit) {
      std::ostringstream msg;
      msg << what << " " << values.data()[k] << " (element " << k << ") exceeds the limit of "
          << limit << " (the file is corrupt or not a learned skill)";
      fail(where, msg.str());
    }
  }
  return values;
}

Eigen::MatrixXd weights(const json& j, const std::string& where, long dims, int num_basis) {
  if (!j.is_array()) fail(where, "expected an array of per-dimension weight arrays");
  if (static_cast<long>(j.size()) != dims) {
    fail(where,
         "expected " + std::to_string(dims) + " weight arrays, got " + std::to_string(j.size()));
  }
  Eigen::MatrixXd w(num_basis, dims);
  for (long d = 0; d < dims; ++d) {
    w.col(d) = vector(j[static_cast<size_t>(d)], where + "[" + std::to_string(d) + "]", num_basis);
  }
  return bounded(w, kMaxWeightMagnitude, where, "weight");
}

Eigen::Quaterniond quaternion(const json& j, const std::string& where) {
  const Eigen::VectorXd v = vector(j, where, 4);
  if (v.norm() < 1e-6) fail(where, "quaternion has zero norm");
  return Eigen::Quaterniond(v[0], v[1], v[2], v[3]).normalized();
}

json poseJson(const lfd::Pose& p) {
  return json{{"position", vectorJson(p.position)}, {"orientation", quaternionJson(p.orientation)}};
}

lfd::Pose poseFromJson(const json& j, const std::string& where) {
  lfd::Pose p;
  p.position = bounded(vector(member(j, "position", where), where + ".position", 3),
                       kMaxPositionMagnitude, where + ".position", "position");
  p.orientation = quaternion(member(j, "orientation", where), where + ".orientation");
  return p;
}

// A spread may be infinite (the frame is undefined in some demo): JSON null.
json spreadJson(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}

double spreadFromJson(const json& j, const std::string& where) {
  if (j.is_null()) return std::numeric_limits<double>::infinity();
  const double v = number(j, where);
  if (v < 0.0) fail(where, "a spread must be >= 0");
  return v;
}

lfd::SceneFrame frameFromJson(const json& j, const std::string& where) {
  try {
    return lfd::SceneFrame::parse(text(j, where));
  } catch (const std::invalid_argument& e) {
    fail(where, e.what());
  }
}

json goalJson(const lfd::SegmentGoalModel& g) {
  json candidates = json::array();
  for (const lfd::FrameSpread& c : g.candidates)
    candidates.push_back(json{{"frame", c.frame.name()},
                              {"position_spread_m", spreadJson(c.position_m)},
                              {"orientation_spread_rad", spreadJson(c.orientation_rad)}});
  return json{{"position",
               {{"frame", g.position_frame.name()},
                {"offset", vectorJson(g.position_offset)},
                {"spread_m", spreadJson(g.position_spread)}}},
              {"orientation",
               {{"frame", g.orientation_frame.name()},
                {"offset", quaternionJson(g.orientation_offset)},
                {"spread_rad", spreadJson(g.orientation_spread)}}},
              {"heading",
               {{"frame", g.motion_frame ? g.motion_frame->name() : ""},
                {"spread_rad", spreadJson(g.motion_spread)}}},
              {"candidates", candidates}};
}

lfd::SegmentGoalModel goalFromJson(const json& j, const std::string& w) {
  lfd::SegmentGoalModel g;
  const json& p = member(j, "position", w);
  g.position_frame = frameFromJson(member(p, "frame", w + ".position"), w + ".position.frame");
  g.position_offset =
      bounded(vector(member(p, "offset", w + ".position"), w + ".position.offset", 3),
              kMaxPositionMagnitude, w + ".position.offset", "position");
  g.position_spread =
      spreadFromJson(member(p, "spread_m", w + ".position"), w + ".position.spread_m");
  const json& o = member(j, "orientation", w);
  g.orientation_frame =
      frameFromJson(member(o, "frame", w + ".orientation"), w + ".orientation.frame");
  g.orientation_offset =
      quaternion(member(o, "offset", w + ".orientation"), w + ".orientation.offset");
  g.orientation_spread =
      spreadFromJson(member(o, "spread_rad", w + ".orientation"), w + ".orientation.spread_rad");
  const json& h = member(j, "heading", w);
  const std::string motion = text(member(h, "frame", w + ".heading"), w + ".heading.frame");
  if (!motion.empty()) g.motion_frame = frameFromJson(motion, w + ".heading.frame");
  g.motion_spread =
      spreadFromJson(member(h, "spread_rad", w + ".heading"), w + ".heading.spread_rad");
  if (j.contains("candidates")) {
    const json& c = j["candidates"];
    if (!c.is_array()) fail(w + ".candidates", "expected an array");
    for (size_t i = 0; i < c.size(); ++i) {
      const std::string wc = w + ".candidates[" + std::to_string(i) + "]";
      g.candidates.push_back({frameFromJson(member(c[i], "frame", wc), wc + ".frame"),
                              spreadFromJson(member(c[i], "position_spread_m", wc), wc),
                              spreadFromJson(member(c[i], "orientation_spread_rad", wc), wc)});
    }
  }
  return g;
}

json sceneJson(const std::string& id, const DemoScene& d) {
  json objects = json::object();
  for (const auto& [name, pose] : d.scene.objects) objects[name] = poseJson(pose);
  return json{{"demo_id", id},
              {"start", poseJson(d.start)},
              {"objects", objects},
              {"goal", poseJson(d.scene.goal)}};
}

std::pair<std::string, DemoScene> sceneFromJson(const json& j, const std::string& w) {
  DemoScene d;
  const std::string id = text(member(j, "demo_id", w), w + ".demo_id");
  d.start = poseFromJson(member(j, "start", w), w + ".start");
  d.scene.goal = poseFromJson(member(j, "goal", w), w + ".goal");
  const json& objects = member(j, "objects", w);
  if (!objects.is_object()) fail(w + ".objects", "expected an object of named poses");
  for (const auto& [name, pose] : objects.items())
    d.scene.objects[name] = poseFromJson(pose, w + ".objects." + name);
  return {id, d};
}

lfd::TimeAlignmentOptions alignmentFromJson(const json& j) {
  const std::string w = "time_alignment";
  lfd::TimeAlignmentOptions a;
  a.sample_seconds = number(member(j, "sample_seconds", w), w + ".sample_seconds");
  if (!(a.sample_seconds > 0.0)) fail(w + ".sample_seconds", "must be > 0 (s)");
  a.warp_sigma = number(member(j, "warp_sigma", w), w + ".warp_sigma");
  if (!(a.warp_sigma >= 0.0)) fail(w + ".warp_sigma", "must be >= 0 (s)");
  const json& yaw = member(j, "yaw_invariant", w);
  if (!yaw.is_boolean()) fail(w + ".yaw_invariant", "expected true or false");
  a.yaw_invariant = yaw.get<bool>();
  return a;
}

}  // namespace

json toJson(const lfd::DmpParameters& p) {
  return json{{"num_basis", p.num_basis},
              {"alpha_x", p.alpha_x},
              {"width_scale", p.width_scale},
              {"alpha_z", p.alpha_z},
              {"beta_z", p.beta_z},
              {"ridge", p.ridge},
              {"derivative_half_window", p.derivatives.half_window},
              {"derivative_poly_order", p.derivatives.poly_order}};
}

json toJson(const lfd::SegmentDmp& dmp) {
  json j{{"tau", dmp.tau}};
  if (dmp.position) {
    const auto& p = *dmp.position;
    j["position"] = json{{"start", vectorJson(p.start())},
                         {"goal", vectorJson(p.goal())},
                         {"start_velocity", vectorJson(p.startVelocity())},
                         {"weights", weightsJson(p.weights())}};
  }
  if (dmp.orientation) {
    const auto& o = *dmp.orientation;
    j["orientation"] = json{{"start", quaternionJson(o.start())},
                            {"goal", quaternionJson(o.goal())},
                            {"start_angular_velocity", vectorJson(o.startAngularVelocity())},
                            {"weights", weightsJson(o.weights())}};
  }
  if (dmp.gripper) {
    const auto& g = *dmp.gripper;
    j["gripper"] = json{{"start", g.start()[0]},
                        {"goal", g.goal()[0]},
                        {"start_velocity", g.startVelocity()[0]},
                        {"weights", vectorJson(g.weights().col(0))}};
  }
  if (!dmp.warnings.empty()) j["warnings"] = dmp.warnings;
  return j;
}

json toJson(const SkillLibrary& lib) {
  json segments = json::array();
  for (const auto& seg : lib.segments) {
    json demos = json::array();
    for (const auto& d : seg.demos) {
      demos.push_back(json{{"demo_id", d.demo_id},
                           {"start_time", d.start_time},
                           {"end_time", d.end_time},
                           {"parameters", vectorJson(d.parameters)},
                           {"dmp", toJson(d.dmp)}});
    }
    json j{{"index", seg.index}, {"name", seg.name}, {"demos", demos}};
    if (seg.goal) j["goal"] = goalJson(*seg.goal);
    if (!seg.time_reference.empty()) j["time_reference"] = seg.time_reference;
    segments.push_back(j);
  }
  json scenes = json::array();
  for (const auto& [id, scene] : lib.demo_scenes) scenes.push_back(sceneJson(id, scene));
  json out{{"format", kSkillLibraryFormat},
           {"version", lib.version},
           {"task", lib.task},
           {"features", lib.features},
           {"generalization_parameters", lib.generalization_parameters},
           {"position_names", lib.position_names},
           {"dmp_parameters", toJson(lib.dmp_parameters)},
           {"smoothing_sigma", lib.smoothing_sigma},
           {"cartesian_frame", lib.cartesian_frame},
           {"demo_scenes", scenes},
           {"segments", segments}};
  if (lib.sensory_signature) out["sensory_signature"] = toJson(*lib.sensory_signature);
  if (lib.time_alignment) {
    const lfd::TimeAlignmentOptions& a = *lib.time_alignment;
    out["time_alignment"] = json{{"sample_seconds", a.sample_seconds},
                                 {"warp_sigma", a.warp_sigma},
                                 {"yaw_invariant", a.yaw_invariant}};
  }
  return out;
}

lfd::DmpParameters dmpParametersFromJson(const json& j, const std::string& where) {
  lfd::DmpParameters p;
  const double nb = number(member(j, "num_basis", where), where + ".num_basis");
  if (nb != std::floor(nb)) fail(where + ".num_basis", "must be an integer");
  p.num_basis = static_cast<int>(nb);
  p.alpha_x = number(member(j, "alpha_x", where), where + ".alpha_x");
  p.width_scale = number(member(j, "width_scale", where), where + ".width_scale");
  p.alpha_z = number(member(j, "alpha_z", where), where + ".alpha_z");
  p.beta_z = number(member(j, "beta_z", where), where + ".beta_z");
  p.ridge = number(member(j, "ridge", where), where + ".ridge");
  p.derivatives.half_window = static_cast<int>(
      number(member(j, "derivative_half_window", where), where + ".derivative_half_window"));
  p.derivatives.poly_order = static_cast<int>(
      number(member(j, "derivative_poly_order", where), where + ".derivative_poly_order"));
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    fail(where, e.what());
  }
  return p;
}

lfd::SegmentDmp segmentDmpFromJson(const json& j, const lfd::DmpParameters& params,
                                   const std::string& where) {
  lfd::SegmentDmp dmp;
  dmp.params = params;
  dmp.tau = number(member(j, "tau", where), where + ".tau");
  if (!(dmp.tau > 0.0)) fail(where + ".tau", "must be positive");
  const int n = params.num_basis;
  try {
    if (j.contains("position")) {
      const std::string w = where + ".position";
      const json& p = j["position"];
      const Eigen::VectorXd goal = bounded(vector(member(p, "goal", w), w + ".goal"),
                                           kMaxPositionMagnitude, w + ".goal", "position");
      const long d = goal.size();
      if (d < 1) fail(w + ".goal", "needs at least one dimension");
      dmp.position.emplace(params, dmp.tau, weights(member(p, "weights", w), w + ".weights", d, n),
                           bounded(vector(member(p, "start", w), w + ".start", d),
                                   kMaxPositionMagnitude, w + ".start", "position"),
                           goal, vector(member(p, "start_velocity", w), w + ".start_velocity", d));
    }
    if (j.contains("orientation")) {
      const std::string w = where + ".orientation";
      const json& o = j["orientation"];
      dmp.orientation.emplace(
          params, dmp.tau, weights(member(o, "weights", w), w + ".weights", 3, n),
          quaternion(member(o, "start", w), w + ".start"),
          quaternion(member(o, "goal", w), w + ".goal"),
          vector(member(o, "start_angular_velocity", w), w + ".start_angular_velocity", 3));
    }
    if (j.contains("gripper")) {
      const std::string w = where + ".gripper";
      const json& g = j["gripper"];
      Eigen::MatrixXd gw(n, 1);
      gw.col(0) = bounded(vector(member(g, "weights", w), w + ".weights", n), kMaxWeightMagnitude,
                          w + ".weights", "weight");
      dmp.gripper.emplace(params, dmp.tau, gw,
                          Eigen::VectorXd::Constant(1, number(member(g, "start", w), w + ".start")),
                          Eigen::VectorXd::Constant(1, number(member(g, "goal", w), w + ".goal")),
                          Eigen::VectorXd::Constant(
                              1, number(member(g, "start_velocity", w), w + ".start_velocity")));
    }
    if (j.contains("warnings")) {
      for (const auto& s : j["warnings"]) dmp.warnings.push_back(text(s, where + ".warnings"));
    }
    dmp.validate();
  } catch (const std::invalid_argument& e) {
    fail(where, e.what());
  }
  return dmp;
}

namespace {

void checkFormatAndVersion(const json& j, const std::string& root) {
  const std::string format = text(member(j, "format", root), "format");
  if (format != kSkillLibraryFormat) {
    fail("format", "expected \"" + std::string(kSkillLibraryFormat) + "\", got \"" + format + "\"");
  }
  const double version = number(member(j, "version", root), "version");
  if (version == 1) {
    fail("version",
         "version 1 has no learned segment goals (they were rules in the executor's "
         "config): relearn the library with this build (learn_skills.py or "
         "/learner/learn)");
  }
  if (version != kSkillLibraryVersion) {
    fail("version", "unsupported version " + std::to_string(static_cast<int>(version)) +
                        " (this build reads version " + std::to_string(kSkillLibraryVersion) + ")");
  }
}

/// `param_dims` is the parameter count of the segment's earlier demos (-1: this is the first).
DemoSkill demoSkillFromJson(const json& j, const std::string& wd, const SkillLibrary& lib,
                            long param_dims) {
  DemoSkill demo;
  demo.demo_id = text(member(j, "demo_id", wd), wd + ".demo_id");
  demo.start_time = number(member(j, "start_time", wd), wd + ".start_time");
  demo.end_time = number(member(j, "end_time", wd), wd + ".end_time");
  demo.parameters = vector(member(j, "parameters", wd), wd + ".parameters", param_dims);
  demo.dmp = segmentDmpFromJson(member(j, "dmp", wd), lib.dmp_parameters, wd + ".dmp");
  if (demo.dmp.position &&
      demo.dmp.position->dims() != static_cast<int>(lib.position_names.size())) {
    fail(wd + ".dmp.position", "has " + std::to_string(demo.dmp.position->dims()) +
                                   " dimensions but position_names has " +
                                   std::to_string(lib.position_names.size()));
  }
  return demo;
}

// Every demo of a segment has the same DMP parts, so they generalize into one.
void checkSameDmpParts(const lfd::SegmentDmp& ref, const lfd::SegmentDmp& dmp,
                       const std::string& wd) {
  if (ref.position.has_value() != dmp.position.has_value() ||
      ref.orientation.has_value() != dmp.orientation.has_value() ||
      ref.gripper.has_value() != dmp.gripper.has_value()) {
    fail(wd + ".dmp", "has different parts (position/orientation/gripper) than demos[0]");
  }
}

SegmentSkills segmentFromJson(const json& j, const std::string& ws, const SkillLibrary& lib) {
  SegmentSkills seg;
  seg.index = static_cast<int>(number(member(j, "index", ws), ws + ".index"));
  seg.name = text(member(j, "name", ws), ws + ".name");
  if (j.contains("goal")) seg.goal = goalFromJson(j["goal"], ws + ".goal");
  if (j.contains("time_reference"))
    seg.time_reference = text(j["time_reference"], ws + ".time_reference");
  const json& demos = member(j, "demos", ws);
  if (!demos.is_array()) fail(ws + ".demos", "expected an array");
  long param_dims = -1;
  for (size_t d = 0; d < demos.size(); ++d) {
    const std::string wd = ws + ".demos[" + std::to_string(d) + "]";
    DemoSkill demo = demoSkillFromJson(demos[d], wd, lib, param_dims);
    param_dims = demo.parameters.size();
    if (!seg.demos.empty()) checkSameDmpParts(seg.demos.front().dmp, demo.dmp, wd);
    seg.demos.push_back(std::move(demo));
  }
  return seg;
}

}  // namespace

SkillLibrary skillLibraryFromJson(const json& j) {
  const std::string root = "skill library";
  SkillLibrary lib;
  checkFormatAndVersion(j, root);
  lib.version = kSkillLibraryVersion;
  lib.task = text(member(j, "task", root), "task");
  lib.features = texts(member(j, "features", root), "features");
  lib.generalization_parameters =
      text(member(j, "generalization_parameters", root), "generalization_parameters");
  lib.position_names = texts(member(j, "position_names", root), "position_names");
  lib.dmp_parameters = dmpParametersFromJson(member(j, "dmp_parameters", root), "dmp_parameters");
  if (j.contains("smoothing_sigma")) {
    lib.smoothing_sigma = number(j["smoothing_sigma"], "smoothing_sigma");
    if (!(lib.smoothing_sigma >= 0.0)) fail("smoothing_sigma", "must be >= 0 (s)");
  }
  if (j.contains("time_alignment")) lib.time_alignment = alignmentFromJson(j["time_alignment"]);
  lib.cartesian_frame = text(member(j, "cartesian_frame", root), "cartesian_frame");
  if (j.contains("demo_scenes")) {
    const json& scenes = j["demo_scenes"];
    if (!scenes.is_array()) fail("demo_scenes", "expected an array");
    for (size_t i = 0; i < scenes.size(); ++i)
      lib.demo_scenes.insert(sceneFromJson(scenes[i], "demo_scenes[" + std::to_string(i) + "]"));
  }
  const json& segments = member(j, "segments", root);
  if (!segments.is_array()) fail("segments", "expected an array");
  for (size_t s = 0; s < segments.size(); ++s) {
    lib.segments.push_back(
        segmentFromJson(segments[s], "segments[" + std::to_string(s) + "]", lib));
  }
  if (j.contains("sensory_signature")) {
    lib.sensory_signature = signatureFromJson(j["sensory_signature"], "sensory_signature");
    if (lib.sensory_signature->segments.size() != lib.segments.size())
      fail("sensory_signature.segments",
           "has " + std::to_string(lib.sensory_signature->segments.size()) +
               " segments, the library " + std::to_string(lib.segments.size()));
  }
  return lib;
}

lfd::OutputKind skillLibraryOutput() {
  return lfd::jsonOutput("skill library", kSkillLibraryFormat);
}

void saveSkillLibrary(const SkillLibrary& library, const std::string& path, bool overwrite,
                      const LibraryLimits& limits) {
  const json j = toJson(library);
  checkLibrarySizes(j, limits);  // a library lfd writes is one it loads again
  // Demo ids and segment names come from requests and file names: invalid UTF-8 is written as
  // U+FFFD rather than throwing nlohmann's type_error 316 at the end of a whole learning run.
  const std::string text = j.dump(2, ' ', false, json::error_handler_t::replace);
  lfd::writeTextAtomically(path, overwrite, skillLibraryOutput(), text + "\n");
}

SkillLibrary loadSkillLibrary(const std::string& path, const LibraryLimits& limits) {
  const std::string name = lfd::quoted(path);
  std::optional<lfd::InputFile> file;  // opened once: the size checked is the file parsed
  try {
    file.emplace(lfd::openInputFile(path));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("cannot open skill library: ") + e.what());
  }
  // Bounded before parsing: the parse costs ~11x the file in memory (300 MB took 3.3 GB).
  const std::uintmax_t bytes = file->size();
  if (bytes > limits.max_file_bytes)
    throw std::runtime_error(name + ": " + std::to_string(bytes) + " bytes, over the limit of " +
                             std::to_string(limits.max_file_bytes) +
                             " (library_limits/max_file_bytes)");
  std::ifstream in(file->readPath());
  if (!in) throw std::runtime_error("cannot open skill library " + name);
  json j;
  try {
    in >> j;
  } catch (const json::parse_error& e) {
    throw std::runtime_error(name + ": not valid JSON: " + e.what());
  }
  try {
    checkLibrarySizes(j, limits);
    SkillLibrary library = skillLibraryFromJson(j);
    checkLibraryDurations(library, limits);
    return library;
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(name + ": " + e.what());
  }
}

}  // namespace lfd_dmp
