// CSV trajectories for the master-free dmp_tool: a header row, a time column, any number of
// position columns, optional quaternion columns qw,qx,qy,qz and an optional gripper column. A
// trajectory dmp_tool writes starts with the comment line kTrajectoryCsvMarker, which marks it as
// lfd's (--overwrite replaces only such a file) and which the reader skips.
#pragma once

#include <lfd_core/dmp/segment_dmp.hpp>
#include <lfd_core/io/safe_paths.hpp>

#include <string>
#include <vector>

namespace lfd_dmp {

struct CsvColumns {
  std::string time;                 ///< empty: "t", "time" or "stamp" if present, else column 0
  std::string gripper = "gripper";  ///< used when present
  std::size_t max_rows = 1000000;   ///< data rows read at most (a 10M-row file took 1.9 GB)
  double max_abs_value = 1e100;     ///< |value| accepted (squares must not overflow)
};

struct CsvTrajectory {
  std::vector<std::string> position_names;
  lfd::SegmentDemo demo;
};

/// The first line of every trajectory CSV lfd writes.
constexpr const char* kTrajectoryCsvMarker = "# lfd trajectory (dmp_tool rollout)";
/// What a trajectory CSV is, for outputs: a file whose first line is kTrajectoryCsvMarker.
lfd::OutputKind trajectoryCsvOutput();

/// Throws std::runtime_error naming the file, line and column of the first problem (missing
/// header, ragged row, non-numeric or non-finite value, partial quaternion columns, UTF-16). A
/// UTF-8 byte-order mark and a first kTrajectoryCsvMarker line are skipped.
CsvTrajectory readTrajectoryCsv(const std::string& path, const CsvColumns& columns = {});

/// Writes kTrajectoryCsvMarker, then t, the position columns, qw,qx,qy,qz (if any) and gripper (if
/// any), atomically; an existing file is kept (std::invalid_argument) unless `overwrite`, and even
/// then unless it is a trajectory CSV lfd wrote.
void writeTrajectoryCsv(const std::string& path, const lfd::SegmentTrajectory& trajectory,
                        const std::vector<std::string>& position_names, bool overwrite);

}  // namespace lfd_dmp
