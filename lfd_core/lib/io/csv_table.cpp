#include "lfd_core/io/csv_table.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "lfd_core/io/safe_paths.hpp"
#include "lfd_core/io/user_text.hpp"

namespace lfd {
namespace {

bool isPadding(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '"';
}

std::string trimmed(const std::string& s) {
  std::size_t begin = 0, end = s.size();
  while (begin < end && isPadding(s[begin])) ++begin;
  while (end > begin && isPadding(s[end - 1])) --end;
  return s.substr(begin, end - begin);
}

std::vector<std::string> splitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(
        trimmed(line.substr(start, comma == std::string::npos ? comma : comma - start)));
    if (comma == std::string::npos) return cells;
    start = comma + 1;
  }
}

std::string cellText(const char* p) {  // the rest of one cell, for an error message
  const char* end = p;
  while (*end != '\0' && *end != ',') ++end;
  return trimmed(std::string(p, end));
}

}  // namespace

CsvReader::CsvReader(const std::string& path, CsvReadOptions options)
    : path_(path), options_(std::move(options)) {
  try {
    const InputFile file = openInputFile(path);  // opened once: no FIFO swapped in
    in_.open(file.readPath());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("cannot open CSV file: ") + e.what());
  }
  if (!in_) throw std::invalid_argument("cannot open CSV file " + quoted(path));
  std::string line;
  while (std::getline(in_, line)) {
    if (++line_number_ == 1) {
      // A spreadsheet's UTF-8 byte-order mark would make the first column "\xef\xbb\xbftime".
      stripByteOrderMark(line, path);
      if (!options_.skip_first_line.empty() && trimmed(line) == options_.skip_first_line) continue;
    }
    if (!trimmed(line).empty()) break;
  }
  if (trimmed(line).empty()) fail("is empty (expected a header row)");
  header_ = splitCells(line);
  for (std::size_t c = 0; c < header_.size(); ++c)
    if (header_[c].empty()) fail("column " + std::to_string(c + 1) + " of the header has no name");
}

int CsvReader::column(const std::string& name) const {
  for (std::size_t c = 0; c < header_.size(); ++c)
    if (header_[c] == name) return static_cast<int>(c);
  return -1;
}

void CsvReader::fail(const std::string& what) const {
  throw std::invalid_argument("CSV file " + quoted(path_) + ": " + what);
}

void CsvReader::failAt(std::size_t column, const std::string& what) const {
  const std::string name = column < header_.size() ? quoted(header_[column]) : "?";
  fail("line " + std::to_string(line_number_) + ", column " + std::to_string(column + 1) + " (" +
       name + "): " + what);
}

CsvTable CsvReader::readRows() {
  CsvTable table;
  table.header = header_;
  std::string line;
  std::size_t rows = 0;
  while (std::getline(in_, line)) {
    ++line_number_;
    if (trimmed(line).empty()) continue;
    if (++rows > options_.max_rows) {
      fail("has more than " + std::to_string(options_.max_rows) + " data rows (" +
           options_.max_rows_key + ")");
    }
    parseRow(line, table);
  }
  if (rows == 0) fail("has no data rows");
  return table;
}

// Parsed in place (no string per cell): feature files reach a million rows.
void CsvReader::parseRow(const std::string& line, CsvTable& table) const {
  const char* p = line.c_str();
  std::size_t column = 0;
  while (true) {
    while (*p == ' ' || *p == '\t' || *p == '"') ++p;
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    const char* after = end;
    while (isPadding(*after)) ++after;
    if (end == p || (*after != ',' && *after != '\0'))
      failAt(column, quoted(cellText(p)) + " is not a number");
    if (column >= header_.size()) {
      fail("line " + std::to_string(line_number_) + " has more than " +
           std::to_string(header_.size()) + " columns, as many as the header");
    }
    if (!std::isfinite(v) && options_.finite_only)
      failAt(column, quoted(cellText(p)) + " is not finite");
    if (std::isfinite(v) && std::abs(v) > options_.max_abs_value) {
      std::ostringstream text;
      text << v << " is beyond +-" << options_.max_abs_value << " (" << options_.max_abs_value_key
           << ")";
      failAt(column, text.str());
    }
    table.values.push_back(v);
    ++column;
    if (*after == '\0') break;
    p = after + 1;
  }
  if (column != header_.size()) {
    fail("line " + std::to_string(line_number_) + " has " + std::to_string(column) +
         " columns, the header " + std::to_string(header_.size()));
  }
}

}  // namespace lfd
