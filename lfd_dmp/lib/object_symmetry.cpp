#include "lfd_dmp/object_symmetry.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace lfd_dmp {

namespace {

constexpr std::size_t kMaxRotations = 24;

bool known(const std::vector<Eigen::Quaterniond>& rotations, const Eigen::Quaterniond& q) {
  for (const Eigen::Quaterniond& r : rotations)
    if (r.angularDistance(q) < 1e-6) return true;
  return false;
}

Eigen::Quaterniond turn(int order, const Eigen::Vector3d& axis, const char* name) {
  if (order != 1 && order != 2 && order != 3 && order != 4 && order != 6)
    throw std::invalid_argument(std::string("object symmetry: the order about ") + name +
                                " must be 1, 2, 3, 4 or 6, got " + std::to_string(order));
  return Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * M_PI / order, axis));
}

}  // namespace

ObjectSymmetry symmetryOfOrders(int x, int y, int z) {
  const std::vector<Eigen::Quaterniond> generators{turn(x, Eigen::Vector3d::UnitX(), "x"),
                                                   turn(y, Eigen::Vector3d::UnitY(), "y"),
                                                   turn(z, Eigen::Vector3d::UnitZ(), "z")};
  ObjectSymmetry out{{Eigen::Quaterniond::Identity()}};
  // Closure: every product of a known rotation and a generator, until nothing new appears.
  for (std::size_t i = 0; i < out.rotations.size(); ++i) {
    for (const Eigen::Quaterniond& g : generators) {
      const Eigen::Quaterniond next = (out.rotations[i] * g).normalized();
      if (known(out.rotations, next)) continue;
      if (out.rotations.size() == kMaxRotations)
        throw std::invalid_argument(
            "object symmetry: these turns do not close into a finite group of at most 24 "
            "rotations (a cube's)");
      out.rotations.push_back(next);
    }
  }
  return out;
}

lfd::Pose canonicalPose(const SkillLibrary& library, const std::string& name, const lfd::Pose& pose,
                        const ObjectSymmetry& symmetry) {
  lfd::Pose best = pose;
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [id, demo] : library.demo_scenes) {
    const auto seen = demo.scene.objects.find(name);
    if (seen == demo.scene.objects.end()) continue;
    for (const Eigen::Quaterniond& r : symmetry.rotations) {
      const Eigen::Quaterniond q = (pose.orientation * r).normalized();
      const double angle = q.angularDistance(seen->second.orientation);
      if (angle < nearest - 1e-9) {
        nearest = angle;
        best.orientation = q;
      }
    }
  }
  return best;
}

lfd::Scene canonicalScene(const SkillLibrary& library, const lfd::Scene& scene,
                          const std::map<std::string, ObjectSymmetry>& symmetries) {
  lfd::Scene out = scene;
  for (auto& [name, pose] : out.objects) {
    const auto s = symmetries.find(name);
    if (s != symmetries.end()) pose = canonicalPose(library, name, pose, s->second);
  }
  return out;
}

}  // namespace lfd_dmp
