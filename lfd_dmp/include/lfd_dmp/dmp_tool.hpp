// Master-free command line around the DMP core and the skill library (nodes/dmp_tool.cpp is a
// thin main over this, so tests drive the very same code path). Outputs are written atomically;
// an existing --out is kept unless --overwrite, and --out never replaces the command's input.
//
//   dmp_tool learn   --csv demo.csv --out skill.json [--task NAME] [--basis N] [--overwrite]
//                    [--time-column NAME] [--gripper-column NAME]
//   dmp_tool rollout --library skill.json --out traj.csv [--segment I] [--demo J | --generalize]
//                    [--start x,y,..] [--goal x,y,..] [--start-quat w,x,y,z] [--goal-quat w,x,y,z]
//                    [--start-gripper v] [--goal-gripper v] [--tau s] [--dt s] [--duration s]
//                    [--goal-filter rate] [--overwrite]
//   dmp_tool info    --library skill.json
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace lfd_dmp {

/// args excludes the program name. Returns the process exit code (0 ok, 1 runtime error,
/// 2 usage error); messages go to out / err.
int runDmpTool(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace lfd_dmp
