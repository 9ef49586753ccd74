#include "lfd_core/io/ros_message_schema.hpp"

#include <algorithm>
#include <cctype>
#include <functional>
#include <map>
#include <sstream>

namespace lfd::rosmsg {

std::size_t builtinSize(Kind kind) {
  switch (kind) {
    case Kind::kBool:
    case Kind::kInt8:
    case Kind::kUint8:
      return 1;
    case Kind::kInt16:
    case Kind::kUint16:
      return 2;
    case Kind::kInt32:
    case Kind::kUint32:
    case Kind::kFloat32:
      return 4;
    case Kind::kInt64:
    case Kind::kUint64:
    case Kind::kFloat64:
    case Kind::kTime:
    case Kind::kDuration:
      return 8;
    case Kind::kString:
    case Kind::kMessage:
      return 0;
  }
  return 0;
}

bool isNumeric(Kind kind) {
  return kind != Kind::kString && kind != Kind::kMessage;
}

int MessageType::fieldIndex(const std::string& field) const {
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (fields[k].name == field) return static_cast<int>(k);
  }
  return -1;
}

namespace {

std::optional<Kind> builtinKind(const std::string& name) {
  static const std::map<std::string, Kind> kInds{
      {"bool", Kind::kBool},        {"int8", Kind::kInt8},     {"byte", Kind::kInt8},
      {"uint8", Kind::kUint8},      {"char", Kind::kUint8},    {"int16", Kind::kInt16},
      {"uint16", Kind::kUint16},    {"int32", Kind::kInt32},   {"uint32", Kind::kUint32},
      {"int64", Kind::kInt64},      {"uint64", Kind::kUint64}, {"float32", Kind::kFloat32},
      {"float64", Kind::kFloat64},  {"string", Kind::kString}, {"time", Kind::kTime},
      {"duration", Kind::kDuration}};
  const auto it = kInds.find(name);
  if (it == kInds.end()) return std::nullopt;
  return it->second;
}

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

bool isIdentifier(const std::string& s) {
  if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

bool isSeparator(const std::string& line) {
  const std::string t = trim(line);
  return t.size() >= 3 && t.find_first_not_of('=') == std::string::npos;
}

std::string packageOf(const std::string& type) {
  const auto slash = type.find('/');
  return slash == std::string::npos ? "" : type.substr(0, slash);
}

// One message's text: its name and lines (line numbers kept for the errors).
struct Block {
  std::string name;
  std::vector<std::pair<std::size_t, std::string>> lines;
};

std::vector<Block> splitBlocks(const std::string& datatype, const std::string& definition) {
  std::vector<Block> blocks{{datatype, {}}};
  std::istringstream in(definition);
  std::string line;
  bool expect_name = false;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (isSeparator(line)) {
      expect_name = true;
      continue;
    }
    const std::string t = trim(line);
    if (expect_name) {
      if (t.empty()) continue;
      if (t.rfind("MSG:", 0) != 0) {
        throw MessageError("line " + std::to_string(number) +
                           ": expected 'MSG: pkg/Type' after a separator, got '" + t + "'");
      }
      blocks.push_back({trim(t.substr(4)), {}});
      expect_name = false;
      continue;
    }
    blocks.back().lines.emplace_back(number, line);
  }
  return blocks;
}

// "float64[7]" -> base "float64", length 7; "Point[]" -> kVariableLength.
std::pair<std::string, int> splitArray(const std::string& token, const std::string& where) {
  const auto open = token.find('[');
  if (open == std::string::npos) return {token, kScalar};
  if (token.back() != ']') throw MessageError(where + ": bad type '" + token + "'");
  const std::string inside = token.substr(open + 1, token.size() - open - 2);
  if (inside.empty()) return {token.substr(0, open), kVariableLength};
  if (!std::all_of(inside.begin(), inside.end(),
                   [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }) ||
      inside.size() > 9) {
    throw MessageError(where + ": bad array length in '" + token + "'");
  }
  return {token.substr(0, open), std::stoi(inside)};
}

// Parses one line into a field (returns true) or a constant (appended to `type`).
bool parseLine(const std::string& raw, const std::string& package, const std::string& where,
               MessageType& type, FieldDefinition& field) {
  std::string line = trim(raw);
  if (line.empty() || line[0] == '#') return false;
  const auto space = line.find_first_of(" \t");
  if (space == std::string::npos)
    throw MessageError(where + ": expected 'type name', got '" + line + "'");
  const std::string type_token = line.substr(0, space);
  std::string rest = line.substr(space + 1);
  const auto equals = rest.find('=');
  const auto hash = rest.find('#');
  const auto [base, length] = splitArray(type_token, where);
  const std::optional<Kind> builtin = builtinKind(base);
  if (equals != std::string::npos && (hash == std::string::npos || equals < hash)) {
    // A constant: "int32 X=1", "string S=text # kept" (a string constant's value is the rest).
    const std::string name = trim(rest.substr(0, equals));
    std::string value = rest.substr(equals + 1);
    if (base != "string") value = value.substr(0, value.find('#'));
    if (!builtin || length != kScalar || !isIdentifier(name)) {
      throw MessageError(where + ": bad constant '" + line + "'");
    }
    type.constants.push_back(name + "=" + trim(value));
    return false;
  }
  const std::string name = trim(rest.substr(0, hash));
  if (!isIdentifier(name)) throw MessageError(where + ": bad field name in '" + line + "'");
  field = FieldDefinition{};
  field.name = name;
  field.array_length = length;
  if (builtin) {
    field.kind = *builtin;
    field.type_name = base;
  } else {
    field.kind = Kind::kMessage;
    if (base == "Header" || base == "std_msgs/Header") {
      field.type_name = "std_msgs/Header";
    } else if (base.find('/') != std::string::npos) {
      field.type_name = base;
    } else {
      field.type_name = package.empty() ? base : package + "/" + base;
    }
  }
  return true;
}

std::size_t findType(const std::vector<MessageType>& types, const FieldDefinition& field,
                     const std::string& user) {
  for (std::size_t k = 0; k < types.size(); ++k) {
    if (types[k].name == field.type_name) return k;
  }
  // A definition may name a type of another package without its prefix; accept a unique match
  // on the short name rather than fail on a quirk of the recording tool.
  const std::string short_name = field.type_name.substr(field.type_name.rfind('/') + 1);
  std::vector<std::size_t> matches;
  for (std::size_t k = 0; k < types.size(); ++k) {
    const std::string& n = types[k].name;
    if (n.substr(n.rfind('/') + 1) == short_name) matches.push_back(k);
  }
  if (matches.size() == 1) return matches[0];
  throw MessageError("the definition of " + field.type_name + " (field '" + field.name + "' of " +
                     user + ") is missing from the message definition");
}

// No real message is a terabyte; the cap keeps every size sum and product far from overflowing.
constexpr std::size_t kMaxMessageBytes = std::size_t(1) << 40;

std::size_t cappedProduct(std::size_t count, std::size_t item, const std::string& type) {
  if (item != 0 && count > kMaxMessageBytes / item)
    throw MessageError("message type " + type + " has fixed arrays larger than 1 TB");
  return count * item;
}

// Fixed and minimal sizes, bottom-up; a type that contains itself (not valid ROS) is rejected so
// that no walk can recurse forever.
void computeSizes(std::vector<MessageType>& types) {
  enum class State { kTodo, kBusy, kDone };
  std::vector<State> state(types.size(), State::kTodo);
  std::function<void(std::size_t)> visit = [&](std::size_t k) {
    if (state[k] == State::kDone) return;
    if (state[k] == State::kBusy)
      throw MessageError("message type " + types[k].name + " contains itself");
    state[k] = State::kBusy;
    std::optional<std::size_t> size = 0;
    std::size_t min_size = 0;
    for (const FieldDefinition& f : types[k].fields) {
      std::optional<std::size_t> element;
      std::size_t element_min = 4;  // a string's length
      if (f.kind == Kind::kMessage) {
        visit(f.message);
        element = types[f.message].fixed_size;
        element_min = types[f.message].min_size;
      } else if (f.kind != Kind::kString) {
        element = builtinSize(f.kind);
        element_min = *element;
      }
      const std::size_t count = f.array_length >= 0 ? static_cast<std::size_t>(f.array_length) : 1;
      if (f.array_length == kVariableLength) {
        size.reset();
        min_size += 4;
      } else {
        min_size += cappedProduct(count, element_min, types[k].name);
        if (size && element) {
          *size += cappedProduct(count, *element, types[k].name);
        } else {
          size.reset();
        }
      }
    }
    if (min_size > kMaxMessageBytes || (size && *size > kMaxMessageBytes))
      throw MessageError("message type " + types[k].name + " has fixed arrays larger than 1 TB");
    types[k].fixed_size = size;
    types[k].min_size = min_size;
    state[k] = State::kDone;
  };
  for (std::size_t k = 0; k < types.size(); ++k) visit(k);
}

}  // namespace

MessageSchema MessageSchema::parse(const std::string& datatype, const std::string& definition) {
  if (datatype.empty()) throw MessageError("message definition without a type name");
  MessageSchema schema;
  for (const Block& block : splitBlocks(datatype, definition)) {
    MessageType type;
    type.name = block.name == "Header" ? "std_msgs/Header" : block.name;
    const std::string package = packageOf(type.name);
    for (const auto& [number, line] : block.lines) {
      FieldDefinition field;
      const std::string where = type.name + " (definition line " + std::to_string(number) + ")";
      if (parseLine(line, package, where, type, field)) {
        if (type.fieldIndex(field.name) >= 0)
          throw MessageError(where + ": field '" + field.name + "' defined twice");
        type.fields.push_back(std::move(field));
      }
    }
    schema.types_.push_back(std::move(type));
  }
  for (MessageType& type : schema.types_) {
    for (FieldDefinition& field : type.fields) {
      if (field.kind != Kind::kMessage) continue;
      field.message = findType(schema.types_, field, type.name);
      field.type_name = schema.types_[field.message].name;
    }
  }
  computeSizes(schema.types_);
  return schema;
}

}  // namespace lfd::rosmsg
