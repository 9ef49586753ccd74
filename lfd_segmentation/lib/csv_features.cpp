#include "lfd_segmentation/csv_features.hpp"

#include <sstream>
#include <stdexcept>

#include "lfd_core/io/csv_table.hpp"
#include "lfd_core/io/user_text.hpp"
#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd_segmentation {

namespace {

int timeColumn(const lfd::CsvReader& csv, const std::string& time_column) {
  if (!time_column.empty()) {
    const int index = csv.column(time_column);
    if (index < 0) csv.fail("has no time column " + lfd::quoted(time_column));
    return index;
  }
  for (const char* name : {"time", "t", "timestamp", "stamp"}) {
    const int index = csv.column(name);
    if (index >= 0) return index;
  }
  return -1;
}

}  // namespace

lfd::FeatureMatrix readCsvFeatures(const std::string& path, const std::string& time_column,
                                   double rate, const RequestLimits& limits) {
  lfd::CsvReadOptions options;
  options.max_rows = limits.max_csv_rows;
  options.max_rows_key = "limits/max_csv_rows";
  options.max_abs_value = limits.max_abs_value;
  options.max_abs_value_key = "limits/max_abs_value: distances would overflow";
  lfd::CsvReader csv(path, options);  // NaN/Inf kept: the pipeline reports them by feature
  const int time_index = timeColumn(csv, time_column);
  lfd::FeatureMatrix m;
  for (std::size_t c = 0; c < csv.header().size(); ++c)
    if (static_cast<int>(c) != time_index) m.names.push_back(csv.header()[c]);
  if (limits.max_features > 0 && m.names.size() > limits.max_features) {  // before any row
    csv.fail("has " + std::to_string(m.names.size()) + " feature columns, over the limit of " +
             std::to_string(limits.max_features) + " (limits/max_features)");
  }
  if (m.names.empty()) csv.fail("has no feature column");
  const lfd::CsvTable table = csv.readRows();
  const std::size_t rows = table.rows();
  m.data.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(m.names.size()));
  for (std::size_t r = 0; r < rows; ++r) {
    Eigen::Index f = 0;
    for (std::size_t c = 0; c < table.header.size(); ++c)
      if (static_cast<int>(c) != time_index)
        m.data(static_cast<Eigen::Index>(r), f++) = table.at(r, c);
  }
  if (rate > 0) {  // an explicit rate overrides the time column (e.g. stamps of a bad clock)
    m.time.resize(rows);
    for (std::size_t r = 0; r < rows; ++r) m.time[r] = r / rate;
  } else if (time_index >= 0) {
    m.time.resize(rows);
    for (std::size_t r = 0; r < rows; ++r)
      m.time[r] = table.at(r, static_cast<std::size_t>(time_index));
  }
  return m;
}

std::string clockGapWarning(const lfd::FeatureMatrix& matrix, const std::string& path,
                            double max_missing) {
  if (matrix.time.size() < 3) return "";
  std::size_t row = 1;  // the row after the largest step
  for (std::size_t r = 2; r < matrix.time.size(); ++r)
    if (matrix.time[r] - matrix.time[r - 1] > matrix.time[row] - matrix.time[row - 1]) row = r;
  const double gap = matrix.time[row] - matrix.time[row - 1];
  double median = 0.0;  // the pipeline's own step
  try {
    median = 1.0 / lfd::sampleRateOf(matrix);
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
