// Message definitions and the field reader on hand-made definitions and hand-serialized bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "lfd_core/io/ros_message_reader.hpp"
#include "lfd_core/io/ros_message_schema.hpp"
#include "ros_serialized_bytes.hpp"

namespace {

using lfd::rosmsg::FieldReader;
using lfd::rosmsg::Kind;
using lfd::rosmsg::MessageError;
using lfd::rosmsg::MessageSchema;
using lfd::rosmsg::UnknownField;

// A made-up type that uses every construct: comments, constants (a string constant keeps its
// '#'), Header, builtins and aliases, fixed and variable arrays, strings, time and duration,
// nested types with and without their package.
const char* const kSampleDefinition = R"(# A sample for the reader tests
Header header
int32 MODE_A=1     # a constant is part of the type, not of the bytes
string NOTE=keep # this
uint8 mode
bool flag
string label       # not a number
float32 ratio
float64[3] fixed
float64[] values
string[] names
Point p
test_pkg/Item[] items
time t
duration d
uint8[] blob
byte small
char letter
int64 big
================================================================================
MSG: std_msgs/Header
uint32 seq
time stamp
string frame_id
================================================================================
MSG: test_pkg/Point
float64 x
float64 y
float64 z
================================================================================
MSG: test_pkg/Item
string id
Point position
int16[] counts
)";

MessageSchema sampleSchema() {
  return MessageSchema::parse("test_pkg/Sample", kSampleDefinition);
}

struct Item {
  std::string id;
  double x, y, z;
  std::vector<std::int16_t> counts;
};

Bytes sampleBytes(std::uint32_t stamp_sec = 100, std::vector<Item> items = {}) {
  if (items.empty()) items = {{"leg", 1, 2, 3, {7, -8}}, {"top", 4, 5, 6, {}}};
  Bytes b;
  b.put<std::uint32_t>(42).put<std::uint32_t>(stamp_sec).put<std::uint32_t>(500000000).str("base");
  b.put<std::uint8_t>(3).put<std::uint8_t>(1).str("hello").put<float>(0.25f);
  for (double v : {1.5, 2.5, 3.5}) b.put(v);
  b.put<std::uint32_t>(3);
  for (double v : {10.0, 20.0, 30.0}) b.put(v);
  b.put<std::uint32_t>(3).str("a").str("bb").str("c");
  b.put(3.0).put(4.0).put(12.0);  // p: norm 13
  b.put<std::uint32_t>(static_cast<std::uint32_t>(items.size()));
  for (const Item& it : items) {
    b.str(it.id).put(it.x).put(it.y).put(it.z);
    b.put<std::uint32_t>(static_cast<std::uint32_t>(it.counts.size()));
    for (std::int16_t c : it.counts) b.put(c);
  }
  b.put<std::uint32_t>(7).put<std::uint32_t>(250000000);  // t = 7.25 s
  b.put<std::int32_t>(-2).put<std::int32_t>(500000000);   // d = -1.5 s
  b.put<std::uint32_t>(4)
      .put<std::uint8_t>(9)
      .put<std::uint8_t>(8)
      .put<std::uint8_t>(255)
      .put<std::uint8_t>(6);
  b.put<std::int8_t>(-5).put<std::uint8_t>(200).put<std::int64_t>(-1234567890123LL);
  return b;
}

TEST(RosMessageSchema, ParsesEveryConstruct) {
  const MessageSchema s = sampleSchema();
  const auto& root = s.root();
  EXPECT_EQ(root.name, "test_pkg/Sample");
  ASSERT_EQ(root.fields.size(), 16u);  // constants are not fields
  EXPECT_EQ(root.constants, (std::vector<std::string>{"MODE_A=1", "NOTE=keep # this"}));
  const auto& header = root.fields[root.fieldIndex("header")];
  EXPECT_EQ(header.type_name, "std_msgs/Header");
  EXPECT_EQ(s.type(header.message).name, "std_msgs/Header");
  const auto& p = root.fields[root.fieldIndex("p")];
  EXPECT_EQ(p.type_name, "test_pkg/Point");  // resolved in the user's package
  EXPECT_EQ(s.type(p.message).fixed_size, 24u);
  const auto& items = root.fields[root.fieldIndex("items")];
  EXPECT_EQ(items.array_length, lfd::rosmsg::kVariableLength);
  EXPECT_EQ(s.type(items.message).fields[1].type_name, "test_pkg/Point");
  EXPECT_FALSE(s.type(items.message).fixed_size.has_value());
  EXPECT_EQ(root.fields[root.fieldIndex("fixed")].array_length, 3);
  EXPECT_EQ(root.fields[root.fieldIndex("small")].kind, Kind::kInt8);    // byte
  EXPECT_EQ(root.fields[root.fieldIndex("letter")].kind, Kind::kUint8);  // char
  EXPECT_EQ(root.fields[root.fieldIndex("t")].kind, Kind::kTime);
  EXPECT_EQ(root.fields[root.fieldIndex("d")].kind, Kind::kDuration);
  EXPECT_FALSE(root.fixed_size.has_value());
}

TEST(RosMessageSchema, BadDefinitionsAreErrors) {
  auto parse = [](const std::string& text) { return MessageSchema::parse("p/T", text); };
  EXPECT_THROW(parse("Missing m\n"), MessageError);  // p/Missing is not defined
  EXPECT_THROW(parse("float64\n"), MessageError);
  EXPECT_THROW(parse("float64 a b\n"), MessageError);
  EXPECT_THROW(parse("float64[x] a\n"), MessageError);
  EXPECT_THROW(parse("float64 a\nint32 a\n"), MessageError);
  EXPECT_THROW(parse("float64 a\n====\nfloat64 b\n"), MessageError);  // no MSG: line
  EXPECT_THROW(parse("p/T inner\n"), MessageError);                   // contains itself
  EXPECT_THROW(parse("float64[999999999] a\nU[999999999] u\n===\nMSG: p/U\nfloat64[999999999] b\n"),
               MessageError);  // absurd fixed sizes
  try {
    parse("Missing m\n");
  } catch (const MessageError& e) {
    EXPECT_NE(std::string(e.what()).find("p/Missing"), std::string::npos) << e.what();
  }
  // Whitespace, comment-only lines and a missing trailing newline are fine.
  const MessageSchema ok = parse("  # comment\n\n  float64   a   # c\nstring s");
  EXPECT_EQ(ok.root().fields.size(), 2u);
  EXPECT_EQ(ok.root().fixed_size, std::nullopt);
}

TEST(RosMessageReader, ReadsNestedArraysStringsTimeByPath) {
  const MessageSchema s = sampleSchema();
  const Bytes b = sampleBytes();
  const std::vector<std::string> paths{"mode",
                                       "flag",
                                       "ratio",
                                       "fixed/2",
                                       "values/1",
                                       "values/bb",
                                       "p/norm",
                                       "items/1/position/x",
                                       "items/0/counts/1",
                                       "t",
                                       "d",
                                       "blob/2",
                                       "small",
                                       "letter",
                                       "big",
                                       "header/seq",
                                       "header/stamp",
                                       "p/y"};
  FieldReader reader(s, paths);
  reader.read(b.data.data(), b.data.size());
  const std::vector<double> expected{
      3, 1, 0.25, 3.5, 20, 20, 13, 4, -8, 7.25, -1.5, 255, -5, 200, -1234567890123.0, 42, 100.5, 4};
  ASSERT_EQ(reader.size(), paths.size());
  for (std::size_t k = 0; k < paths.size(); ++k) {
    EXPECT_TRUE(reader.present(k)) << paths[k];
    EXPECT_DOUBLE_EQ(reader.value(k), expected[k]) << paths[k];
  }
  EXPECT_DOUBLE_EQ(reader.headerStamp(), 100.5);
}

TEST(RosMessageReader, ElementsAMessageDoesNotCarryAreAbsent) {
  const MessageSchema s = sampleSchema();
  FieldReader reader(s,
                     {"values/5", "values/zz", "items/2/position/x", "items/1/counts/0", "mode"});
  const Bytes b = sampleBytes();
  reader.read(b.data.data(), b.data.size());
  for (std::size_t k = 0; k < 4; ++k) EXPECT_FALSE(reader.present(k)) << k;
  EXPECT_TRUE(reader.present(4));
  // The same reader on a message with three items sees the third.
  const Bytes more = sampleBytes(0, {{"a", 0, 0, 0, {1}}, {"b", 0, 0, 0, {2}}, {"c", 9, 0, 0, {}}});
  reader.read(more.data.data(), more.data.size());
  EXPECT_TRUE(reader.present(2));
  EXPECT_DOUBLE_EQ(reader.value(2), 9.0);
  EXPECT_TRUE(reader.present(3));
  EXPECT_DOUBLE_EQ(reader.headerStamp(), 0.5);  // 0 s + 0.5 s
}

TEST(RosMessageReader, TruncatedExtendedOrCorruptBytesAreErrors) {
  const MessageSchema s = sampleSchema();
  const Bytes b = sampleBytes();
  FieldReader reader(s, {"big", "items/1/position/z"});
  // Every truncation, read through a buffer of exactly that size (so a sanitizer would catch
  // any read past it).
  for (std::size_t n = 0; n < b.data.size(); ++n) {
    std::vector<std::uint8_t> cut(b.data.begin(), b.data.begin() + n);
    EXPECT_THROW(reader.read(cut.data(), cut.size()), MessageError) << n;
  }
  std::vector<std::uint8_t> longer = b.data;
  longer.push_back(0);
  EXPECT_THROW(reader.read(longer.data(), longer.size()), MessageError);
  // A corrupt element count (values) claims far more than the buffer holds.
  std::vector<std::uint8_t> corrupt = b.data;
  const std::size_t values_count = 4 + 8 + 4 + 4 + 1 + 1 + 4 + 5 + 4 + 24;
  const std::uint32_t huge = 0x40000000;
  std::memcpy(corrupt.data() + values_count, &huge, 4);
  try {
    reader.read(corrupt.data(), corrupt.size());
    FAIL() << "corrupt count accepted";
  } catch (const MessageError& e) {
    EXPECT_NE(std::string(e.what()).find("'values'"), std::string::npos) << e.what();
  }
  reader.read(b.data.data(), b.data.size());  // still usable after errors
  EXPECT_DOUBLE_EQ(reader.value(1), 6.0);
}

std::string unknownMessage(const MessageSchema& s, const Bytes& b, const std::string& path) {
  try {
    lfd::rosmsg::expandFields(s, b.data.data(), b.data.size(), {path});
  } catch (const UnknownField& e) {
    return e.what();
  }
  return "";
}

TEST(RosMessageReader, UnknownPathsListTheFields) {
  const MessageSchema s = sampleSchema();
  const Bytes b = sampleBytes();
  const std::string e = unknownMessage(s, b, "items/0/position/w");
  EXPECT_NE(e.find("no field 'items/0/position/w'"), std::string::npos) << e;
  EXPECT_NE(e.find("has no field 'w' (it has x, y, z, norm)"), std::string::npos) << e;
  for (const char* listed : {"\n  header/stamp\n", "\n  values/<0..2> or <name: a, bb, c>\n",
                             "\n  items/<0..1>/position/x\n", "\n  items/<0..1>/counts/<0..1>\n",
                             "\n  fixed/<0..2>\n", "\n  p/norm\n", "\n  blob/<0..3>\n"}) {
    EXPECT_NE(e.find(listed), std::string::npos) << listed << " not in " << e;
  }
  EXPECT_EQ(e.find("label"), std::string::npos) << "strings are not numbers: " << e;
  EXPECT_NE(unknownMessage(s, b, "label").find("is a string"), std::string::npos);
  EXPECT_NE(unknownMessage(s, b, "values").find("add an index, a name or *"), std::string::npos);
  EXPECT_NE(unknownMessage(s, b, "p").find("with fields x, y, z"), std::string::npos);
  EXPECT_NE(unknownMessage(s, b, "fixed/3").find("has 3 elements"), std::string::npos);
  // Names index variable arrays only: a fixed array's elements mean their position.
  EXPECT_NE(unknownMessage(s, b, "fixed/a").find("float64[3]: index it with a number"),
            std::string::npos);
  const MessageSchema plain = MessageSchema::parse("p/T", "float64[] a\n");
  Bytes two;
  two.put<std::uint32_t>(2).put(1.0).put(2.0);
  EXPECT_NE(unknownMessage(plain, two, "a/x").find("without a string[]"), std::string::npos);
  EXPECT_NE(unknownMessage(s, b, "items/leg/id").find("index it with a number"), std::string::npos);
  EXPECT_NE(unknownMessage(s, b, "mode/x").find("has no fields"), std::string::npos);
  EXPECT_THROW(FieldReader(s, {"p/w"}), UnknownField);
  EXPECT_THROW(FieldReader(s, {"values/*"}), UnknownField);
  EXPECT_THROW(FieldReader(s, {"a//b"}), UnknownField);
}

TEST(RosMessageReader, WildcardsExpandOverTheSample) {
  const MessageSchema s = sampleSchema();
  const Bytes b = sampleBytes();
  auto expand = [&](const std::string& p) {
    return lfd::rosmsg::expandFields(s, b.data.data(), b.data.size(), {p});
  };
  EXPECT_EQ(expand("values/*"), (std::vector<std::string>{"values/a", "values/bb", "values/c"}));
  EXPECT_EQ(expand("fixed/*"), (std::vector<std::string>{"fixed/0", "fixed/1", "fixed/2"}));
  EXPECT_EQ(expand("items/*/position/x"),
            (std::vector<std::string>{"items/0/position/x", "items/1/position/x"}));
  EXPECT_EQ(expand("items/*/counts/*"),
            (std::vector<std::string>{"items/0/counts/0", "items/0/counts/1"}));
  EXPECT_EQ(expand("/p/x"), (std::vector<std::string>{"p/x"}));
  EXPECT_EQ(lfd::rosmsg::arrayLength(s, b.data.data(), b.data.size(), "items"), 2u);
  EXPECT_EQ(lfd::rosmsg::stringValues(s, b.data.data(), b.data.size(), "items/1/id"),
            (std::vector<std::string>{"top"}));
}

// sensor_msgs/JointState and a JointTrajectoryControllerState-like type: names index arrays,
// in the array's own message or in an enclosing one (joint_names).
TEST(RosMessageReader, NamesIndexArraysFromTheNearestKeyArray) {
  const MessageSchema joints = MessageSchema::parse(
      "sensor_msgs/JointState",
      "Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n"
      "================================================================================\n"
      "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n");
  Bytes b;
  b.put<std::uint32_t>(1).put<std::uint32_t>(0).put<std::uint32_t>(0).str("");
  b.put<std::uint32_t>(2).str("elbow").str("wrist");
  b.put<std::uint32_t>(2).put(0.5).put(-0.5);
  b.put<std::uint32_t>(2).put(1.0).put(2.0);
  b.put<std::uint32_t>(0);  // no effort
  FieldReader r(joints, {"position/wrist", "velocity/elbow", "effort/elbow"});
  r.read(b.data.data(), b.data.size());
  EXPECT_DOUBLE_EQ(r.value(0), -0.5);
  EXPECT_DOUBLE_EQ(r.value(1), 1.0);
  EXPECT_FALSE(r.present(2));
  EXPECT_DOUBLE_EQ(r.headerStamp(), 0.0);  // zero stamp: the caller uses the receive time

  const MessageSchema state =
      MessageSchema::parse("ctrl/State",
                           "string[] joint_names\nPoint actual\nPoint error\n"
                           "===\nMSG: ctrl/Point\nfloat64[] positions\n");
  Bytes c;
  c.put<std::uint32_t>(2).str("j0").str("j1");
  c.put<std::uint32_t>(2).put(1.0).put(2.0);
  c.put<std::uint32_t>(2).put(-0.1).put(-0.2);
  FieldReader s(state, {"actual/positions/j1", "error/positions/0"});
  s.read(c.data.data(), c.data.size());
  EXPECT_DOUBLE_EQ(s.value(0), 2.0);
  EXPECT_DOUBLE_EQ(s.value(1), -0.1);
  EXPECT_EQ(lfd::rosmsg::expandFields(state, c.data.data(), c.data.size(), {"error/positions/*"}),
            (std::vector<std::string>{"error/positions/j0", "error/positions/j1"}));
}

}  // namespace

namespace {

// Arrays of messages whose order is not fixed (a world model's objects, /tf's transforms): an
// element chosen by the value of one of its fields.
TEST(RosMessageReader, ElementsSelectedByAFieldValue) {
  const MessageSchema s = sampleSchema();
  const Bytes b =
      sampleBytes(1, {{"leg", 1, 2, 3, {7}}, {"top", 4, 5, 6, {8, 9}}, {"top", 7, 0, 0, {}}});
  FieldReader r(s, {"items/id=top/position/x", "items/id=top/counts/1", "items/id=leg/position/z",
                    "items/id=nope/position/x", "items/1/position/y", "header/seq"});
  r.read(b.data.data(), b.data.size());
  EXPECT_DOUBLE_EQ(r.value(0), 4.0);  // the first match
  EXPECT_DOUBLE_EQ(r.value(1), 9.0);
  EXPECT_DOUBLE_EQ(r.value(2), 3.0);
  EXPECT_FALSE(r.present(3));
  EXPECT_DOUBLE_EQ(r.value(4), 5.0);  // indices and selectors together
  EXPECT_DOUBLE_EQ(r.value(5), 42.0);
  // Reordered elements: the selector follows the element, the index does not.
  const Bytes swapped = sampleBytes(1, {{"top", 4, 5, 6, {8, 9}}, {"leg", 1, 2, 3, {7}}});
  r.read(swapped.data.data(), swapped.data.size());
  EXPECT_DOUBLE_EQ(r.value(0), 4.0);
  EXPECT_DOUBLE_EQ(r.value(2), 3.0);
  EXPECT_DOUBLE_EQ(r.value(4), 2.0);
  // Every truncation is still an error, never a read past the buffer.
  for (std::size_t n = 0; n < b.data.size(); ++n) {
    std::vector<std::uint8_t> cut(b.data.begin(), b.data.begin() + n);
    EXPECT_THROW(r.read(cut.data(), cut.size()), MessageError) << n;
  }
  // Numeric fields select by number; bad selectors name what is wrong.
  const MessageSchema objects = MessageSchema::parse(
      "p/World", "Object[] objects\n===\nMSG: p/Object\nint32 id\nfloat64 x\n");
  Bytes w;
  w.put<std::uint32_t>(2).put<std::int32_t>(13).put(0.5).put<std::int32_t>(0).put(0.25);
  FieldReader o(objects, {"objects/id=0/x", "objects/id=13/x"});
  o.read(w.data.data(), w.data.size());
  EXPECT_DOUBLE_EQ(o.value(0), 0.25);
  EXPECT_DOUBLE_EQ(o.value(1), 0.5);
  EXPECT_THROW(FieldReader(objects, {"objects/id=leg/x"}), UnknownField);
  EXPECT_THROW(FieldReader(objects, {"objects/colour=red/x"}), UnknownField);
  EXPECT_THROW(FieldReader(objects, {"objects/leg/x"}), UnknownField);
}

}  // namespace
