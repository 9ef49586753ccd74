#include "lfd_dmp/trajectory_csv.hpp"

#include <lfd_core/safe_paths.hpp>
#include <lfd_core/user_text.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string field;
  while (std::getline(ss, field, ',')) out.push_back(trim(field));
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

int findColumn(const std::vector<std::string>& header, const std::string& name) {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : static_cast<int>(it - header.begin());
}

}  // namespace

CsvTrajectory readTrajectoryCsv(const std::string& path, const CsvColumns& columns) {
  std::ifstream in;
  try {
    const lfd::InputFile file = lfd::openInputFile(path);  // opened once: no FIFO swapped in
    in.open(file.readPath());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("cannot open CSV file: ") + e.what());
  }
  if (!in) throw std::runtime_error("cannot open CSV file " + path);
  std::string line;
  size_t line_no = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    if (++line_no == 1) {
      // A spreadsheet's UTF-8 byte-order mark would name the first column "\xef\xbb\xbft".
      try {
        lfd::stripByteOrderMark(line, path);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(e.what());
      }
      if (trim(line) == kTrajectoryCsvMarker) continue;  // lfd's own first line
    }
    if (!trim(line).empty()) {
      header = splitCsv(line);
      break;
    }
  }
  if (header.empty()) throw std::runtime_error(path + ": empty file (expected a header row)");

  int time_col = -1;
  if (!columns.time.empty()) {
    time_col = findColumn(header, columns.time);
    if (time_col < 0) throw std::runtime_error(path + ": no time column \"" + columns.time + "\"");
  } else {
    for (const char* name : {"t", "time", "stamp"}) {
      if ((time_col = findColumn(header, name)) >= 0) break;
    }
    if (time_col < 0) time_col = 0;
  }
  const int grip_col = columns.gripper.empty() ? -1 : findColumn(header, columns.gripper);
  int quat_cols[4];
  int quat_found = 0;
  const char* quat_names[4] = {"qw", "qx", "qy", "qz"};
  for (int i = 0; i < 4; ++i) {
    quat_cols[i] = findColumn(header, quat_names[i]);
    if (quat_cols[i] >= 0) ++quat_found;
  }
  if (quat_found != 0 && quat_found != 4) {
    throw std::runtime_error(path + ": quaternion columns must be all of qw,qx,qy,qz (found " +
                             std::to_string(quat_found) + " of 4)");
  }
  CsvTrajectory out;
  std::vector<int> pos_cols;
  for (int c = 0; c < static_cast<int>(header.size()); ++c) {
    if (c == time_col || c == grip_col) continue;
    if (quat_found == 4 && std::find(quat_cols, quat_cols + 4, c) != quat_cols + 4) continue;
    if (header[c].empty())
      throw std::runtime_error(path + ": column " + std::to_string(c) + " has no name");
    pos_cols.push_back(c);
    out.position_names.push_back(header[c]);
  }

  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    if (rows.size() >= columns.max_rows) {
      throw std::runtime_error(path + ": more than " + std::to_string(columns.max_rows) +
                               " data rows (the row limit)");
    }
    const std::vector<std::string> fields = splitCsv(line);
    if (fields.size() != header.size()) {
      throw std::runtime_error(path + ": line " + std::to_string(line_no) + " has " +
                               std::to_string(fields.size()) + " fields, the header has " +
                               std::to_string(header.size()));
    }
    std::vector<double> row(fields.size());
    for (size_t c = 0; c < fields.size(); ++c) {
      const char* begin = fields[c].c_str();
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(begin, &end);
      if (fields[c].empty() || end == begin || *end != '\0' || !std::isfinite(v)) {
        throw std::runtime_error(path + ": line " + std::to_string(line_no) + ", column \"" +
                                 header[c] + "\": \"" + fields[c] + "\" is not a finite number");
      }
      if (std::abs(v) > columns.max_abs_value) {
        throw std::runtime_error(path + ": line " + std::to_string(line_no) + ", column \"" +
                                 header[c] + "\": " + fields[c] + " is beyond +-1e100");
      }
      row[c] = v;
    }
    rows.push_back(std::move(row));
  }
  const Eigen::Index m = static_cast<Eigen::Index>(rows.size());
  if (m == 0) throw std::runtime_error(path + ": no data rows");
  lfd::SegmentDemo& demo = out.demo;
  demo.times.resize(m);
  demo.positions.resize(m, static_cast<Eigen::Index>(pos_cols.size()));
  if (quat_found == 4) demo.quaternions.resize(m, 4);
  if (grip_col >= 0) demo.gripper.resize(m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto& r = rows[static_cast<size_t>(i)];
    demo.times[i] = r[static_cast<size_t>(time_col)];
    for (size_t c = 0; c < pos_cols.size(); ++c)
      demo.positions(i, static_cast<Eigen::Index>(c)) = r[static_cast<size_t>(pos_cols[c])];
    if (quat_found == 4) {
      for (int q = 0; q < 4; ++q) demo.quaternions(i, q) = r[static_cast<size_t>(quat_cols[q])];
    }
    if (grip_col >= 0) demo.gripper[i] = r[static_cast<size_t>(grip_col)];
  }
  return out;
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
