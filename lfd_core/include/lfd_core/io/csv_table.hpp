// The one CSV reader of lfd (the `segment` CLI's feature files, dmp_tool's trajectories): a header
// row names the columns, then one row of numbers per line, comma separated. Cells may be padded
// with spaces or wrapped in double quotes (spreadsheet exports); blank lines are skipped; a UTF-8
// byte-order mark is skipped and UTF-16 is refused ("save it as UTF-8"). Every error names the
// file, the line and the column.
#pragma once

#include <cstddef>
#include <fstream>
#include <string>
#include <vector>

namespace lfd {

struct CsvReadOptions {
  std::string skip_first_line;     ///< a first line equal to this (a writer's marker) is skipped
  std::size_t max_rows = 1000000;  ///< data rows read at most (a 10M-row file took 1.9 GB)
  std::string max_rows_key = "the row limit";  ///< named when the limit is hit
  double max_abs_value = 1e100;  ///< finite |value| accepted: squares must not overflow
  std::string max_abs_value_key = "the value limit";
  bool finite_only = false;  ///< refuse nan/inf cells; else they are kept for the caller
};

/// Rows of numbers, row-major, under the header's names.
struct CsvTable {
  std::vector<std::string> header;
  std::vector<double> values;
  std::size_t rows() const { return header.empty() ? 0 : values.size() / header.size(); }
  double at(std::size_t row, std::size_t column) const {
    return values[row * header.size() + column];
  }
};

/// Reads the header on construction, so that callers check their columns before any row is read.
/// Every error is std::invalid_argument.
class CsvReader {
 public:
  CsvReader(const std::string& path, CsvReadOptions options = {});

  const std::vector<std::string>& header() const { return header_; }
  /// The index of the first column named `name`, or -1.
  int column(const std::string& name) const;
  /// Throws std::invalid_argument "CSV file '<path>': <what>".
  [[noreturn]] void fail(const std::string& what) const;
  /// The data rows (call once); refuses an empty table.
  CsvTable readRows();

 private:
  void parseRow(const std::string& line, CsvTable& table) const;
  [[noreturn]] void failAt(std::size_t column, const std::string& what) const;

  std::string path_;
  CsvReadOptions options_;
  std::ifstream in_;
  std::vector<std::string> header_;
  std::size_t line_number_ = 0;
};

}  // namespace lfd
