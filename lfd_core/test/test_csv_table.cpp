// The one CSV reader (csv_table.hpp): what it accepts from spreadsheets and loggers, and that every
// refusal names the file, the line and the column.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "lfd_core/io/csv_table.hpp"

using namespace std::string_literals;

namespace {

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "csv_table_" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// The message of the std::invalid_argument that reading `text` throws, or "" if none.
std::string refusal(const std::string& text, lfd::CsvReadOptions options = {}) {
  try {
    lfd::CsvReader(writeFile("refused.csv", text), options).readRows();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(CsvTable, ReadsPaddedQuotedCellsAndSkipsBlankLines) {
  const std::string path =
      writeFile("padded.csv", "\xEF\xBB\xBF\"t\", x ,y\r\n\n 0,\"1.5\", -2\r\n1,3,4e-3\n\n");
  lfd::CsvReader csv(path);
  EXPECT_EQ(csv.header(), (std::vector<std::string>{"t", "x", "y"}));  // no BOM in "t"
  EXPECT_EQ(csv.column("y"), 2);
  EXPECT_EQ(csv.column("z"), -1);
  const lfd::CsvTable table = csv.readRows();
  ASSERT_EQ(table.rows(), 2u);
  EXPECT_DOUBLE_EQ(table.at(0, 1), 1.5);
  EXPECT_DOUBLE_EQ(table.at(0, 2), -2.0);
  EXPECT_DOUBLE_EQ(table.at(1, 2), 4e-3);
}

TEST(CsvTable, SkipsTheWritersMarkerLineOnlyWhenAsked) {
  const std::string text = "# made by lfd\nt,x\n0,1\n";
  lfd::CsvReadOptions options;
  options.skip_first_line = "# made by lfd";
  EXPECT_EQ(lfd::CsvReader(writeFile("marker.csv", text), options).header(),
            (std::vector<std::string>{"t", "x"}));
  EXPECT_NE(refusal(text).find("is not a number"), std::string::npos);  // "t,x" read as data
}

TEST(CsvTable, KeepsNonFiniteCellsUnlessFiniteOnly) {
  const std::string text = "t,x\n0,nan\n1,inf\n";
  const lfd::CsvTable table = lfd::CsvReader(writeFile("nan.csv", text)).readRows();
  EXPECT_TRUE(std::isnan(table.at(0, 1)));
  EXPECT_TRUE(std::isinf(table.at(1, 1)));
  lfd::CsvReadOptions finite;
  finite.finite_only = true;
  EXPECT_NE(refusal(text, finite).find("line 2, column 2 ('x'): 'nan' is not finite"),
            std::string::npos)
      << refusal(text, finite);
}

TEST(CsvTable, NamesTheLineAndColumnOfEveryBadRow) {
  EXPECT_NE(refusal("t,x\n0,1\n1,abc\n").find("line 3, column 2 ('x'): 'abc' is not a number"),
            std::string::npos);
  EXPECT_NE(refusal("t,x\n0,1.5kg\n").find("'1.5kg' is not a number"), std::string::npos);
  EXPECT_NE(refusal("t,x\n0,\n").find("line 2, column 2 ('x'): '' is not a number"),
            std::string::npos);
  EXPECT_NE(refusal("t,x\n0\n").find("line 2 has 1 columns, the header 2"), std::string::npos);
  EXPECT_NE(refusal("t,x\n0,1,2\n").find("line 2 has more than 2 columns"), std::string::npos);
  EXPECT_NE(refusal("t,,x\n0,1,2\n").find("column 2 of the header has no name"), std::string::npos);
}

TEST(CsvTable, RefusesEmptyFilesAndTablesWithoutRows) {
  EXPECT_NE(refusal("").find("is empty"), std::string::npos);
  EXPECT_NE(refusal("\n \n").find("is empty"), std::string::npos);
  EXPECT_NE(refusal("t,x\n\n").find("has no data rows"), std::string::npos);
  EXPECT_NE(refusal("\xFF\xFEt\0,\0x\0"s).find("save it as UTF-8"), std::string::npos);
}

TEST(CsvTable, StopsAtItsLimitsNamingTheirKeys) {
  lfd::CsvReadOptions options;
  options.max_rows = 2;
  options.max_rows_key = "limits/max_rows";
  options.max_abs_value = 1e6;
  options.max_abs_value_key = "limits/max_abs";
  EXPECT_NE(refusal("t\n0\n1\n2\n", options).find("more than 2 data rows (limits/max_rows)"),
            std::string::npos);
  EXPECT_NE(refusal("t\n2e6\n", options).find("2e+06 is beyond +-1e+06 (limits/max_abs)"),
            std::string::npos)
      << refusal("t\n2e6\n", options);
}

TEST(CsvTable, RefusesAMissingFileWithItsPath) {
  try {
    lfd::CsvReader csv(testing::TempDir() + "csv_table_missing.csv");
    ADD_FAILURE() << "a missing file was read";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("csv_table_missing.csv"), std::string::npos) << e.what();
  }
}

}  // namespace
