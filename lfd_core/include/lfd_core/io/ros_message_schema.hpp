// ROS 1 message definitions, parsed from the text every bag stores per connection (the top-level
// definition, then one "MSG: pkg/Type" block per dependency after a line of '='). ROS-free: the
// schema drives lfd::rosmsg::FieldReader, which reads numeric fields out of serialized bytes, so a
// bag of any message type can be read without the type's generated C++ code.
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace lfd::rosmsg {

/// Bad definition text or bytes that do not match it (truncated, corrupt, absurd lengths).
struct MessageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// ROS 1 builtin types (byte = int8 and char = uint8 are aliases) and nested messages.
enum class Kind {
  kBool,
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat32,
  kFloat64,
  kTime,      ///< uint32 sec, uint32 nsec; read as seconds
  kDuration,  ///< int32 sec, int32 nsec; read as seconds
  kString,    ///< uint32 length + bytes
  kMessage,
};

/// Serialized size of a fixed-size builtin (0 for kString and kMessage).
std::size_t builtinSize(Kind kind);
/// Numbers, time and duration: what a field path may end on.
bool isNumeric(Kind kind);

constexpr int kScalar = -1;          ///< FieldDefinition::array_length of a plain field
constexpr int kVariableLength = -2;  ///< T[]: uint32 count, then the elements

struct FieldDefinition {
  std::string name;
  Kind kind = Kind::kFloat64;
  std::string type_name;       ///< builtin name, or the resolved "pkg/Type" of a message
  int array_length = kScalar;  ///< kScalar, kVariableLength or the fixed length N of T[N]
  std::size_t message = 0;     ///< index in MessageSchema::types() when kind == kMessage

  bool isArray() const { return array_length != kScalar; }
};

struct MessageType {
  std::string name;  ///< "pkg/Type"
  std::vector<FieldDefinition> fields;
  std::vector<std::string> constants;  ///< "NAME=value": part of the type, not of the bytes
  /// Serialized size when no field (recursively) has a variable size.
  std::optional<std::size_t> fixed_size;
  /// Fewest bytes a message of this type can take (an empty string or array still has its
  /// length): bounds element counts before a walk trusts them.
  std::size_t min_size = 0;

  /// Index of the field called `name`, or -1.
  int fieldIndex(const std::string& name) const;
};

/// A message type and every type it uses. types()[0] is the top-level type.
class MessageSchema {
 public:
  /// Parses a full definition. Field types without a package resolve in the package of the
  /// message that uses them ("Header" is std_msgs/Header); a type the text does not define is
  /// an error. Throws MessageError naming the line.
  static MessageSchema parse(const std::string& datatype, const std::string& definition);

  const MessageType& root() const { return types_.front(); }
  const MessageType& type(std::size_t index) const { return types_.at(index); }
  const std::vector<MessageType>& types() const { return types_; }

 private:
  std::vector<MessageType> types_;
};

}  // namespace lfd::rosmsg
