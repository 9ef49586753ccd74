#include "lfd_dmp/trajectory_csv.hpp"

#include <lfd_core/io/csv_table.hpp>
#include <lfd_core/io/safe_paths.hpp>
#include <lfd_core/io/user_text.hpp>

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

int timeColumn(const lfd::CsvReader& csv, const std::string& time_column) {
  if (!time_column.empty()) {
    const int index = csv.column(time_column);
    if (index < 0) csv.fail("has no time column " + lfd::quoted(time_column));
    return index;
  }
  for (const char* name : {"t", "time", "stamp"}) {
    const int index = csv.column(name);
    if (index >= 0) return index;
  }
  return 0;
}

std::vector<int> quaternionColumns(const lfd::CsvReader& csv) {
  std::vector<int> columns;
  for (const char* name : {"qw", "qx", "qy", "qz"})
    if (csv.column(name) >= 0) columns.push_back(csv.column(name));
  if (!columns.empty() && columns.size() != 4) {
    csv.fail("quaternion columns must be all of qw,qx,qy,qz (found " +
             std::to_string(columns.size()) + " of 4)");
  }
  return columns;
}

CsvTrajectory readTable(const std::string& path, const CsvColumns& columns) {
  lfd::CsvReadOptions options;
  options.skip_first_line = kTrajectoryCsvMarker;
  options.max_rows = columns.max_rows;
  options.max_abs_value = columns.max_abs_value;
  options.finite_only = true;
  lfd::CsvReader csv(path, options);
  const int time_col = timeColumn(csv, columns.time);
  const int grip_col = columns.gripper.empty() ? -1 : csv.column(columns.gripper);
  const std::vector<int> quat_cols = quaternionColumns(csv);
  CsvTrajectory out;
  std::vector<int> pos_cols;
  for (int c = 0; c < static_cast<int>(csv.header().size()); ++c) {
    if (c == time_col || c == grip_col) continue;
    if (std::find(quat_cols.begin(), quat_cols.end(), c) != quat_cols.end()) continue;
    pos_cols.push_back(c);
    out.position_names.push_back(csv.header()[static_cast<size_t>(c)]);
  }
  const lfd::CsvTable table = csv.readRows();
  const Eigen::Index m = static_cast<Eigen::Index>(table.rows());
  lfd::SegmentDemo& demo = out.demo;
  demo.times.resize(m);
  demo.positions.resize(m, static_cast<Eigen::Index>(pos_cols.size()));
  if (!quat_cols.empty()) demo.quaternions.resize(m, 4);
  if (grip_col >= 0) demo.gripper.resize(m);
  auto cell = [&](Eigen::Index row, int column) {
    return table.at(static_cast<size_t>(row), static_cast<size_t>(column));
  };
  for (Eigen::Index i = 0; i < m; ++i) {
    demo.times[i] = cell(i, time_col);
    for (size_t c = 0; c < pos_cols.size(); ++c)
      demo.positions(i, static_cast<Eigen::Index>(c)) = cell(i, pos_cols[c]);
    for (size_t q = 0; q < quat_cols.size(); ++q)
      demo.quaternions(i, static_cast<Eigen::Index>(q)) = cell(i, quat_cols[q]);
    if (grip_col >= 0) demo.gripper[i] = cell(i, grip_col);
  }
  return out;
}

}  // namespace

CsvTrajectory readTrajectoryCsv(const std::string& path, const CsvColumns& columns) {
  try {
    return readTable(path, columns);
  } catch (const std::invalid_argument& e) {  // this reader's contract: std::runtime_error
    throw std::runtime_error(e.what());
  }
}

void writeTrajectoryCsv(const std::string& path, const lfd::SegmentTrajectory& traj,
                        const std::vector<std::string>& position_names, bool overwrite) {
  if (static_cast<Eigen::Index>(position_names.size()) != traj.positions.cols()) {
    throw std::runtime_error("writeTrajectoryCsv: " + std::to_string(position_names.size()) +
                             " position names for " + std::to_string(traj.positions.cols()) +
                             " position columns");
  }
  std::ostringstream out;
  out << kTrajectoryCsvMarker << "\n";
  out << "t";
  for (const auto& n : position_names) out << "," << n;
  const bool quat = traj.quaternions.cols() == 4;
  const bool grip = traj.gripper.size() == traj.times.size() && traj.gripper.size() > 0;
  if (quat) out << ",qw,qx,qy,qz";
  if (grip) out << ",gripper";
  out << "\n" << std::setprecision(10);
  for (Eigen::Index k = 0; k < traj.times.size(); ++k) {
    out << traj.times[k];
    for (Eigen::Index d = 0; d < traj.positions.cols(); ++d) out << "," << traj.positions(k, d);
    if (quat) {
      for (int q = 0; q < 4; ++q) out << "," << traj.quaternions(k, q);
    }
    if (grip) out << "," << traj.gripper[k];
    out << "\n";
  }
  lfd::writeTextAtomically(path, overwrite, trajectoryCsvOutput(), out.str());
}

lfd::OutputKind trajectoryCsvOutput() {
  return lfd::textOutput("trajectory CSV", kTrajectoryCsvMarker);
}

}  // namespace lfd_dmp
