#include "lfd_segmentation/csv_features.hpp"

#include "lfd_core/safe_paths.hpp"
#include "lfd_core/segmentation_pipeline.hpp"
#include "lfd_core/user_text.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace lfd_segmentation {

namespace {

std::string trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r\"");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r\"");
  return s.substr(begin, end - begin + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma == std::string::npos ? comma : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return cells;
}

}  // namespace

lfd::FeatureMatrix read_csv_features(const std::string& path, const std::string& time_column,
                                     double rate, const RequestLimits& limits) {
  std::ifstream in;
  try {
    const lfd::InputFile file = lfd::openInputFile(path);  // opened once: no FIFO swapped in
    in.open(file.readPath());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("cannot open CSV file: ") + e.what());
  }
  if (!in) throw std::invalid_argument("cannot open CSV file " + lfd::quoted(path));
  std::string line;
  std::size_t line_number = 0;
  while (std::getline(in, line)) {
    // A spreadsheet's UTF-8 byte-order mark made the first column "\xef\xbb\xbftime": no time.
    if (++line_number == 1) lfd::stripByteOrderMark(line, path);
    if (!trim(line).empty()) break;
  }
  if (trim(line).empty())
    throw std::invalid_argument("CSV file " + lfd::quoted(path) + " is empty");
  const std::vector<std::string> header = split(line);
  int time_index = -1;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c].empty()) {
      throw std::invalid_argument("CSV file " + lfd::quoted(path) + ": column " +
                                  std::to_string(c + 1) + " of the header has no name");
    }
    const bool is_time = time_column.empty() ? (header[c] == "time" || header[c] == "t" ||
                                                header[c] == "timestamp" || header[c] == "stamp")
                                             : header[c] == time_column;
    if (is_time && time_index < 0) time_index = static_cast<int>(c);
  }
  if (!time_column.empty() && time_index < 0) {
    throw std::invalid_argument("CSV file " + lfd::quoted(path) + " has no time column " +
                                lfd::quoted(time_column));
  }
  lfd::FeatureMatrix m;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (static_cast<int>(c) != time_index) m.names.push_back(header[c]);
  }
  if (limits.max_features > 0 && m.names.size() > limits.max_features) {  // before any row
    throw std::invalid_argument("CSV file " + lfd::quoted(path) + " has " +
                                std::to_string(m.names.size()) +
                                " feature columns, over the limit of " +
                                std::to_string(limits.max_features) + " (limits/max_features)");
  }
  if (m.names.empty())
    throw std::invalid_argument("CSV file " + lfd::quoted(path) + " has no feature column");

  std::vector<double> values;  // row-major while reading
  std::vector<double> time;
  std::size_t rows_read = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (trim(line).empty()) continue;
    if (++rows_read > limits.max_csv_rows) {
      throw std::invalid_argument("CSV file " + lfd::quoted(path) + " has more than " +
                                  std::to_string(limits.max_csv_rows) +
                                  " data rows (limits/max_csv_rows)");
    }
    const char* p = line.c_str();
    std::size_t column = 0;
    while (true) {
      while (*p == ' ' || *p == '\t' || *p == '"') ++p;
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(p, &end);
      if (end == p) {
        throw std::invalid_argument(
            "CSV file " + lfd::quoted(path) + " line " + std::to_string(line_number) + ": column " +
            std::to_string(column + 1) + " (" +
            lfd::quoted(column < header.size() ? header[column] : "?") + ") is not a number");
      }
      if (column >= header.size()) {
        throw std::invalid_argument("CSV file " + lfd::quoted(path) + " line " +
                                    std::to_string(line_number) + " has more than " +
                                    std::to_string(header.size()) + " columns");
      }
      if (std::isfinite(v) && std::abs(v) > limits.max_abs_value) {
        std::ostringstream text;
        text << v << " is beyond +-" << limits.max_abs_value;
        throw std::invalid_argument(
            "CSV file " + lfd::quoted(path) + " line " + std::to_string(line_number) + ", column " +
            std::to_string(column + 1) + " (" + lfd::quoted(header[column]) + "): " + text.str() +
            " (limits/max_abs_value): distances would overflow");
      }
      (static_cast<int>(column) == time_index ? time : values).push_back(v);
      ++column;
      p = end;
      while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '"') ++p;
      if (*p == ',') {
        ++p;
        continue;
      }
      if (*p != '\0') {
        throw std::invalid_argument("CSV file " + lfd::quoted(path) + " line " +
                                    std::to_string(line_number) + ": unexpected '" +
                                    std::string(1, *p) + "'");
      }
      break;
    }
    if (column != header.size()) {
      throw std::invalid_argument("CSV file " + lfd::quoted(path) + " line " +
                                  std::to_string(line_number) + " has " + std::to_string(column) +
                                  " columns, the header " + std::to_string(header.size()));
    }
  }
  const std::size_t rows = values.size() / m.names.size();
  if (rows == 0) throw std::invalid_argument("CSV file " + lfd::quoted(path) + " has no data rows");
  m.data = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      values.data(), rows, m.names.size());
  if (rate > 0) {  // an explicit rate overrides the time column (e.g. stamps of a bad clock)
    m.time.resize(rows);
    for (std::size_t r = 0; r < rows; ++r) m.time[r] = r / rate;
  } else if (time_index >= 0) {
    m.time = std::move(time);
  }
  return m;
}

std::string clock_gap_warning(const lfd::FeatureMatrix& matrix, const std::string& path,
                              double max_missing) {
  if (matrix.time.size() < 3) return "";
  std::size_t row = 1;  // the row after the largest step
  for (std::size_t r = 2; r < matrix.time.size(); ++r)
    if (matrix.time[r] - matrix.time[r - 1] > matrix.time[row] - matrix.time[row - 1]) row = r;
  const double gap = matrix.time[row] - matrix.time[row - 1];
  double median = 0.0;  // the pipeline's own step
  try {
    median = 1.0 / lfd::sample_rate_of(matrix);
  } catch (const std::invalid_argument&) {
    return "";  // a clock that does not increase: the pipeline refuses it, naming the demo
  }
  if (!(gap > max_missing * median)) return "";
  std::ostringstream text;
  text << "'" << path << "': the clock jumps " << gap << " s at row " << row << " (median step "
       << median << " s); the rows are taken as evenly spaced, so put them on a uniform clock with "
       << "--resample HZ";
  return text.str();
}

}  // namespace lfd_segmentation
