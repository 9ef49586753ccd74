#include "lfd_sim_bridge/fault_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace lfd_sim {
namespace {

constexpr double kDefaultHoldingForce = 1e4;  // N: far beyond any arm's pull, a stuck joint

const std::pair<const char*, Fault::Kind> kKinds[] = {
    {"move_object", Fault::Kind::kMoveObject},     {"weaken_grip", Fault::Kind::kWeakenGrip},
    {"freeze_sensor", Fault::Kind::kFreezeSensor}, {"silence_sensor", Fault::Kind::kSilenceSensor},
    {"lock_joint", Fault::Kind::kLockJoint},
};

double holdingForce(const Fault& f) {
  return f.value > 0.0 ? f.value : kDefaultHoldingForce;
}

}  // namespace

Fault::Kind faultKind(const std::string& name) {
  std::string known;
  for (const auto& [n, kind] : kKinds) {
    if (name == n) return kind;
    known += (known.empty() ? "" : ", ") + std::string(n);
  }
  throw std::invalid_argument("unknown fault kind '" + name.substr(0, 64) + "' (kinds: " + known +
                              ")");
}

std::string faultKindName(Fault::Kind kind) {
  for (const auto& [n, k] : kKinds)
    if (k == kind) return n;
  return "?";
}

std::string describeFault(const Fault& f) {
  char text[256];
  switch (f.kind) {
    case Fault::Kind::kMoveObject:
      std::snprintf(text, sizeof(text), "move_object %s to (%.3f, %.3f, %.3f) m at t=%.3f s",
                    f.target.c_str(), f.pose.position[0], f.pose.position[1], f.pose.position[2],
                    f.at);
      break;
    case Fault::Kind::kWeakenGrip:
      std::snprintf(text, sizeof(text), "weaken_grip to %.0f%% of its force at t=%.3f s",
                    100.0 * f.value, f.at);
      break;
    case Fault::Kind::kLockJoint:
      std::snprintf(text, sizeof(text), "lock_joint %s (held up to %.0f N) at t=%.3f s",
                    f.target.c_str(), holdingForce(f), f.at);
      break;
    default:
      std::snprintf(text, sizeof(text), "%s %s at t=%.3f s", faultKindName(f.kind).c_str(),
                    f.target.c_str(), f.at);
  }
  return text;
}

void applyFault(const Fault& f, WorkcellSim* sim) {
  switch (f.kind) {
    case Fault::Kind::kMoveObject:
      sim->setObjectPose(f.target, f.pose);
      break;
    case Fault::Kind::kWeakenGrip:
      sim->weakenGrip(f.value);
      break;
    case Fault::Kind::kFreezeSensor:
      sim->freezeSensor(f.target);
      break;
    case Fault::Kind::kLockJoint:
      sim->lockJoint(f.target, holdingForce(f));
      break;
    case Fault::Kind::kSilenceSensor:
      break;  // the publisher's
  }
}

void FaultSchedule::add(const Fault& f, const WorkcellSim& sim) {
  if (!std::isfinite(f.at)) throw std::invalid_argument("a fault's time must be finite");
  switch (f.kind) {
    case Fault::Kind::kMoveObject:
      sim.checkObjectPose(f.target, f.pose);
      break;
    case Fault::Kind::kWeakenGrip:
      if (!(f.value >= 0.0 && f.value <= 1.0))
        throw std::invalid_argument("weaken_grip keeps a fraction in [0, 1] of the grip, got " +
                                    std::to_string(f.value));
      break;
    case Fault::Kind::kFreezeSensor:
    case Fault::Kind::kSilenceSensor:
      if (!sim.hasSensorGroup(f.target))
        throw std::invalid_argument("no sensor table row '" + f.target.substr(0, 64) + "'");
      break;
    case Fault::Kind::kLockJoint:
      if (!sim.hasJoint(f.target))
        throw std::invalid_argument("no joint '" + f.target.substr(0, 64) + "' to lock");
      if (!std::isfinite(f.value) || f.value < 0.0)
        throw std::invalid_argument("lock_joint's holding force must be finite and >= 0");
      break;
  }
  pending_.push_back(f);
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const Fault& a, const Fault& b) { return a.at < b.at; });
}

std::vector<Fault> FaultSchedule::takeDue(double now) {
  const auto end =
      std::find_if(pending_.begin(), pending_.end(), [now](const Fault& f) { return f.at > now; });
  std::vector<Fault> due(pending_.begin(), end);
  pending_.erase(pending_.begin(), end);
  return due;
}

}  // namespace lfd_sim
