#include "lfd_dmp/dmp_tool.hpp"

#include "lfd_dmp/skill_library.hpp"
#include "lfd_dmp/trajectory_csv.hpp"

#include <lfd_core/dmp/dmp_generalization.hpp>
#include <lfd_core/io/safe_paths.hpp>

#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

constexpr const char* kUsage =
    "usage:\n"
    "  dmp_tool learn   --csv demo.csv --out skill.json [--task NAME] [--basis N] [--overwrite]\n"
    "                   [--time-column NAME] [--gripper-column NAME]\n"
    "  dmp_tool rollout --library skill.json --out traj.csv [--segment I] [--demo J | "
    "--generalize]\n"
    "                   [--overwrite]\n"
    "                   [--start x,y,..] [--goal x,y,..] [--start-quat w,x,y,z] [--goal-quat "
    "w,x,y,z]\n"
    "                   [--start-gripper v] [--goal-gripper v] [--tau s] [--dt s] [--duration s]\n"
    "                   [--goal-filter rate]\n"
    "  dmp_tool info    --library skill.json\n"
    "limits: --basis in [2, 1000]; a rollout holds at most 1000000 samples (duration / dt)\n";

// Bounds of one command (a CLI has no parameter server; the learner's are ~limits in
// config/learner.yaml): work and memory stay bounded whatever the arguments.
constexpr int kMaxBasis = 1000;                   // as ~limits/max_num_basis
constexpr double kMaxRolloutSamples = 1000000.0;  // 1000 s at 1 ms: ~120 MB of rows

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

using Options = std::map<std::string, std::string>;

Options parse(const std::vector<std::string>& args, const std::set<std::string>& valued,
              const std::set<std::string>& flags) {
  Options o;
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (flags.count(a)) {
      o[a] = "1";
    } else if (valued.count(a)) {
      if (i + 1 >= args.size()) throw UsageError(a + " needs a value");
      o[a] = args[++i];
    } else {
      throw UsageError("unknown argument \"" + a + "\" for " + args[0]);
    }
  }
  return o;
}

std::string required(const Options& o, const std::string& key) {
  const auto it = o.find(key);
  if (it == o.end()) throw UsageError("missing " + key);
  return it->second;
}

double toNumber(const std::string& s, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v)) {
    throw UsageError(what + ": \"" + s + "\" is not a finite number");
  }
  return v;
}

Eigen::VectorXd toVector(const std::string& s, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(toNumber(item, what));
  return Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

std::optional<double> optNumber(const Options& o, const std::string& key) {
  const auto it = o.find(key);
  if (it == o.end()) return std::nullopt;
  return toNumber(it->second, key);
}

int learn(const std::vector<std::string>& args, std::ostream& out) {
  const Options o =
      parse(args, {"--csv", "--out", "--task", "--basis", "--time-column", "--gripper-column"},
            {"--overwrite"});
  const std::string csv = required(o, "--csv");
  const bool overwrite = o.count("--overwrite") > 0;
  const std::string path =
      lfd::checkOutputFile(required(o, "--out"), {}, overwrite, {csv}, skillLibraryOutput());
  CsvColumns cols;
  if (o.count("--time-column")) cols.time = o.at("--time-column");
  if (o.count("--gripper-column")) cols.gripper = o.at("--gripper-column");
  const CsvTrajectory traj = readTrajectoryCsv(csv, cols);

  SkillLibrary lib;
  lib.task = o.count("--task") ? o.at("--task") : csv;
  lib.position_names = traj.position_names;
  if (const auto basis = optNumber(o, "--basis")) {
    if (*basis != std::floor(*basis)) throw UsageError("--basis must be an integer");
    if (*basis > kMaxBasis || *basis < 2) {
      throw UsageError("--basis must be in [2, " + std::to_string(kMaxBasis) + "] (the limit)");
    }
    lib.dmp_parameters.num_basis = static_cast<int>(*basis);
  }
  lib.generalization_parameters = traj.demo.positions.cols() > 0 ? "goal_position" : "none";
  DemoSkill skill;
  skill.demo_id = csv;
  skill.start_time = traj.demo.times[0];
  skill.end_time = traj.demo.times[traj.demo.times.size() - 1];
  try {
    skill.dmp = lfd::SegmentDmp::learn(traj.demo, lib.dmp_parameters);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(csv + ": " + e.what());
  }
  skill.parameters = skill.dmp.position ? lfd::goalParameters(skill.dmp) : Eigen::VectorXd();
  for (const auto& w : skill.dmp.warnings) out << "warning: " << w << "\n";
  SegmentSkills seg;
  seg.index = 0;
  seg.name = "segment_0";
  seg.demos.push_back(std::move(skill));
  lib.segments.push_back(std::move(seg));
  saveSkillLibrary(lib, path, overwrite);
  out << "learned a DMP from " << traj.demo.times.size() << " samples ("
      << traj.demo.positions.cols() << " position dims"
      << (traj.demo.quaternions.cols() ? ", orientation" : "")
      << (traj.demo.gripper.size() ? ", gripper" : "") << ") -> " << path << "\n";
  return 0;
}

std::optional<Eigen::Quaterniond> optQuaternion(const Options& o, const std::string& key) {
  if (!o.count(key)) return std::nullopt;
  const Eigen::VectorXd v = toVector(o.at(key), key);
  if (v.size() != 4) throw UsageError(key + " needs 4 numbers w,x,y,z");
  return Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
}

lfd::SegmentRolloutOptions rolloutOptions(const Options& o) {
  lfd::SegmentRolloutOptions ro;
  if (const auto dt = optNumber(o, "--dt")) ro.dt = *dt;
  ro.tau = optNumber(o, "--tau");
  ro.duration = optNumber(o, "--duration");
  ro.goal_filter = optNumber(o, "--goal-filter").value_or(0.0);
  if (o.count("--start")) ro.start_position = toVector(o.at("--start"), "--start");
  if (o.count("--goal")) ro.goal_position = toVector(o.at("--goal"), "--goal");
  ro.start_orientation = optQuaternion(o, "--start-quat");
  ro.goal_orientation = optQuaternion(o, "--goal-quat");
  ro.start_gripper = optNumber(o, "--start-gripper");
  ro.goal_gripper = optNumber(o, "--goal-gripper");
  return ro;
}

// --generalize: the segment's demos generalized to --goal; else the DMP of demo --demo (0).
lfd::SegmentDmp dmpToRollOut(const Options& o, const SegmentSkills& seg,
                             const lfd::SegmentRolloutOptions& ro, std::ostream& out) {
  if (o.count("--generalize")) {
    if (o.count("--demo")) throw UsageError("--demo and --generalize are exclusive");
    if (!ro.goal_position) throw UsageError("--generalize needs --goal");
    std::vector<lfd::SegmentDmp> dmps;
    std::vector<Eigen::VectorXd> params;
    for (const auto& d : seg.demos) {
      dmps.push_back(d.dmp);
      params.push_back(d.parameters);
    }
    const lfd::GeneralizationResult res = lfd::generalizeSegment(dmps, params, *ro.goal_position);
    if (res.outside_demo_range) out << "warning: " << res.warning << "\n";
    out << "generalized from " << dmps.size() << " demos (bandwidth " << res.bandwidth << ")\n";
    return res.dmp;
  }
  const int demo = static_cast<int>(optNumber(o, "--demo").value_or(0));
  if (demo < 0 || demo >= static_cast<int>(seg.demos.size())) {
    throw UsageError("--demo " + std::to_string(demo) + " out of range (segment has " +
                     std::to_string(seg.demos.size()) + " demos)");
  }
  return seg.demos[static_cast<size_t>(demo)].dmp;
}

// The library's position names, or p0, p1, ... when they do not fit the trajectory.
std::vector<std::string> positionColumns(const SkillLibrary& lib,
                                         const lfd::SegmentTrajectory& traj) {
  std::vector<std::string> names = lib.position_names;
  if (static_cast<Eigen::Index>(names.size()) != traj.positions.cols()) {
    names.clear();
    for (Eigen::Index d = 0; d < traj.positions.cols(); ++d)
      names.push_back("p" + std::to_string(d));
  }
  return names;
}

int rollout(const std::vector<std::string>& args, std::ostream& out) {
  const Options o = parse(args,
                          {"--library", "--out", "--segment", "--demo", "--start", "--goal",
                           "--start-quat", "--goal-quat", "--start-gripper", "--goal-gripper",
                           "--tau", "--dt", "--duration", "--goal-filter"},
                          {"--generalize", "--overwrite"});
  const std::string library_path = required(o, "--library");
  const bool overwrite = o.count("--overwrite") > 0;
  const std::string path = lfd::checkOutputFile(required(o, "--out"), {}, overwrite, {library_path},
                                                trajectoryCsvOutput());
  const SkillLibrary lib = loadSkillLibrary(library_path);
  const int seg_index = static_cast<int>(optNumber(o, "--segment").value_or(0));
  if (seg_index < 0 || seg_index >= static_cast<int>(lib.segments.size())) {
    throw UsageError("--segment " + std::to_string(seg_index) + " out of range (library has " +
                     std::to_string(lib.segments.size()) + " segments)");
  }
  const SegmentSkills& seg = lib.segments[static_cast<size_t>(seg_index)];
  if (seg.demos.empty())
    throw std::runtime_error("segment " + std::to_string(seg_index) + " has no demos");

  const lfd::SegmentRolloutOptions ro = rolloutOptions(o);
  const lfd::SegmentDmp dmp = dmpToRollOut(o, seg, ro, out);
  const double samples = ro.duration.value_or(ro.tau.value_or(dmp.tau)) / ro.dt;
  if (!(samples <= kMaxRolloutSamples)) {
    throw UsageError("the rollout would hold " + std::to_string(samples) +
                     " samples (duration / dt), over the limit of 1000000");
  }
  lfd::SegmentTrajectory traj;
  try {
    traj = dmp.rollout(ro);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  writeTrajectoryCsv(path, traj, positionColumns(lib, traj), overwrite);
  out << "rolled out " << traj.times.size() << " steps -> " << path << "\n";
  return 0;
}

int info(const std::vector<std::string>& args, std::ostream& out) {
  const Options o = parse(args, {"--library"}, {});
  const SkillLibrary lib = loadSkillLibrary(required(o, "--library"));
  out << "task " << lib.task << " (version " << lib.version << "), " << lib.segments.size()
      << " segments, " << lib.dmp_parameters.num_basis << " basis functions\n";
  for (const auto& s : lib.segments) {
    out << "  segment " << s.index << " \"" << s.name << "\": " << s.demos.size() << " demos\n";
  }
  return 0;
}

}  // namespace

int runDmpTool(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    (args.empty() ? err : out) << kUsage;
    return args.empty() ? 2 : 0;
  }
  try {
    if (args[0] == "learn") return learn(args, out);
    if (args[0] == "rollout") return rollout(args, out);
    if (args[0] == "info") return info(args, out);
    throw UsageError("unknown command \"" + args[0] + "\"");
  } catch (const UsageError& e) {
    err << "error: " << e.what() << "\n" << kUsage;
    return 2;
  } catch (const std::exception& e) {
    err << "error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace lfd_dmp
