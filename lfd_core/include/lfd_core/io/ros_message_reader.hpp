// Numeric fields of serialized ROS 1 messages, read by path with the message's schema
// (lfd_core/io/ros_message_schema.hpp). ROS-free: the input is the serialized bytes of one message.
//
// A path names fields from the top-level message down, separated by '/':
//   process_value                    a number (bool, integers, floats; time/duration in seconds)
//   error/positions/3                element 3 of an array of numbers
//   objects/0/pose/pose/position/x   element 0 of an array of messages, then its fields
//   objects/id=13/pose/pose/position/x  the first element whose (number or string) field id is 13
//   transforms/child_frame_id=hand/transform/translation/x   (e.g. tf2_msgs/TFMessage)
//   position/elbow_joint             an array of numbers indexed by name: the name is looked up in
//                                    the nearest string[] called name, names or *_names (the
//                                    array's own message first, then the enclosing ones), e.g.
//                                    sensor_msgs/JointState position/<joint> or
//                                    JointTrajectoryControllerState actual/positions/<joint>
//   twist/linear/norm                sqrt(x^2 + y^2 + z^2) of a message with numeric x, y, z and no
//                                    field of its own called norm
// expandFields() also accepts "*" in place of an index or a name: every element of the array in
// a sample message (every name of its key array, when it has one).
//
// Every read is bounds-checked: bytes that do not match the definition throw MessageError, never
// read past the buffer. An element or name a message does not carry is "absent" for that
// message, not an error (arrays may change length from one message to the next).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "lfd_core/io/ros_message_schema.hpp"

namespace lfd::rosmsg {

/// A path that does not name a numeric field of the message; what() says which part failed and
/// what is there instead.
struct UnknownField : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Splits "a/b/3" into {"a", "b", "3"} (a leading '/' is ignored); throws UnknownField on an
/// empty component.
std::vector<std::string> splitPath(const std::string& path);

/// Reads a fixed list of numeric fields from one message after another of the same schema.
class FieldReader {
 public:
  /// Throws UnknownField when a path does not resolve to a number ("*" is not accepted here).
  FieldReader(const MessageSchema& schema, const std::vector<std::string>& paths);
  ~FieldReader();
  FieldReader(FieldReader&&) noexcept;
  FieldReader& operator=(FieldReader&&) noexcept;

  /// Walks one serialized message. Throws MessageError when the bytes do not match the schema
  /// (too short, too long, impossible lengths).
  void read(const std::uint8_t* data, std::size_t size);

  std::size_t size() const;
  /// Whether the last message carried field k (an index or name it has).
  bool present(std::size_t k) const;
  /// Value of field k in the last message (only meaningful when present).
  double value(std::size_t k) const;
  /// header.stamp of the last message (seconds), or 0 when the top-level message has no
  /// std_msgs/Header called header or its stamp is zero.
  double headerStamp() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Replaces every "*" of the patterns by the indices (or key names) of that array in `sample`,
/// and checks every resulting path. Throws UnknownField (listing the message's numeric fields)
/// or MessageError (sample does not match the schema).
std::vector<std::string> expandFields(const MessageSchema& schema, const std::uint8_t* sample,
                                      std::size_t size, const std::vector<std::string>& patterns);

/// Every numeric field path of `sample`, compactly: arrays as "error/positions/<0..6>" plus
/// "<name: a, b, ...>" when indexed by name (at most `max_names` names shown), arrays of messages
/// through their first element ("objects/<0..1>/pose/..."), empty arrays as "<empty>".
std::vector<std::string> listNumericFields(const MessageSchema& schema, const std::uint8_t* sample,
                                           std::size_t size, std::size_t max_names = 8);

/// The length of the array at `path` in `sample` (fixed arrays: their length).
std::size_t arrayLength(const MessageSchema& schema, const std::uint8_t* sample, std::size_t size,
                        const std::string& path);

/// The string (one element) or string[] at `path` in `sample`.
std::vector<std::string> stringValues(const MessageSchema& schema, const std::uint8_t* sample,
                                      std::size_t size, const std::string& path);

/// Gets each string of a message with its field path: "task", "bag_paths[2]",
/// "metadata.header.frame_id", "segmentations[0].source". `value` points into the message bytes.
using StringVisitor = std::function<void(const std::string& path, std::string_view value)>;

/// Walks every field of one serialized message (any depth, every array element) and calls
/// `visit` for each string. Throws MessageError, naming the field, when the bytes do not match
/// the schema (a length past the end, bytes left over).
void forEachString(const MessageSchema& schema, const std::uint8_t* data, std::size_t size,
                   const StringVisitor& visit);

/// Whether the bytes are a message of the schema at all: every length within the buffer and
/// nothing left over (forEachString without a visitor). Throws MessageError naming the field.
void checkMessageBytes(const MessageSchema& schema, const std::uint8_t* data, std::size_t size);

}  // namespace lfd::rosmsg
