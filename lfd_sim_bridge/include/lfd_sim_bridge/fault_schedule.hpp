// Faults scheduled at sim times (tests and benchmarks of execution monitoring, sim
// only). The bridge's ~inject_fault service fills the schedule; each step applies what is due.
// ROS-free: the bridge turns a silenced sensor into a topic that stops, the rest is the workcell's.
#pragma once

#include <string>
#include <vector>

#include "lfd_sim_bridge/workcell_sim.hpp"

namespace lfd_sim {

struct Fault {
  enum class Kind {
    kMoveObject,     ///< target: an object, to `pose` (world); a pose far away removes it
    kWeakenGrip,     ///< `value`: the fraction of the grip's force left, in [0, 1]
    kFreezeSensor,   ///< target: a sensor table row, which repeats its reading
    kSilenceSensor,  ///< target: a sensor table row, whose topic stops
    kLockJoint,      ///< target: a joint, stuck below `value` N (N m) (0: 1e4)
  };
  Kind kind = Kind::kMoveObject;
  std::string target;
  double at = 0.0;  ///< sim s; at or before now: at the next step
  Pose pose;
  double value = 0.0;
};

/// The kind named `name` (move_object, weaken_grip, freeze_sensor, silence_sensor, lock_joint);
/// throws std::invalid_argument listing them.
Fault::Kind faultKind(const std::string& name);
std::string faultKindName(Fault::Kind kind);

/// One line: kind, target, value, when.
std::string describeFault(const Fault& fault);

/// Applies a fault to the workcell (all kinds but kSilenceSensor, which is the publisher's).
void applyFault(const Fault& fault, WorkcellSim* sim);

class FaultSchedule {
 public:
  /// Checks the fault against the workcell (target, value; throws std::invalid_argument naming
  /// what is wrong, and then schedules nothing) and keeps it.
  void add(const Fault& fault, const WorkcellSim& sim);
  /// The faults due at sim time `now`, in time order, removed from the schedule.
  std::vector<Fault> takeDue(double now);
  void clear() { pending_.clear(); }
  std::size_t size() const { return pending_.size(); }

 private:
  std::vector<Fault> pending_;
};

}  // namespace lfd_sim
