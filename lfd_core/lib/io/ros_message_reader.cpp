#include "lfd_core/io/ros_message_reader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

namespace lfd::rosmsg {

// ROS 1 serializes little-endian; the reads below copy bytes straight into host integers.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "ros_message_reader assumes a little-endian host");

namespace {

// ---------------------------------------------------------------------------------------------
// Path resolution against the schema (no bytes involved).

// One step from a message into one of its fields (and, for an array of messages, one element).
struct Hop {
  std::size_t type = 0;   // message type holding the field
  std::size_t field = 0;  // index in that type
  long element = -1;      // element of an array of messages, -1 otherwise
  // Or the first element whose scalar field `match_field` equals `match_value` ("id=13").
  int match_field = -1;
  std::string match_value;
};

enum class End {
  kMessage,  // a message (the root, a nested message or an element of an array of messages)
  kNumber,   // a numeric field
  kArray,    // a whole array (numbers, strings or messages)
  kElement,  // element `index` of an array of builtins
  kKey,      // element of an array of numbers whose key array holds `key`
  kNorm,     // sqrt(x^2 + y^2 + z^2) of the message reached
  kString,   // a string field
};

struct Resolved {
  std::vector<Hop> hops;
  End end = End::kMessage;
  std::size_t message_type = 0;  // kMessage and kNorm: the type reached
  std::uint32_t index = 0;
  std::string key;
  std::size_t key_level = 0;  // the key array is field key_field of the message at this depth
  std::size_t key_field = 0;
  std::array<std::size_t, 3> norm{};
};

std::string join(const std::vector<std::string>& parts, std::size_t count, char sep = '/') {
  std::string out;
  for (std::size_t k = 0; k < count && k < parts.size(); ++k) {
    if (k) out += sep;
    out += parts[k];
  }
  return out;
}

std::string fieldNames(const MessageType& type) {
  std::string out;
  for (const FieldDefinition& f : type.fields) out += (out.empty() ? "" : ", ") + f.name;
  return out.empty() ? "no fields" : out;
}

bool isIndex(const std::string& s) {
  return !s.empty() && s.size() <= 10 &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

bool isKeyArray(const FieldDefinition& f) {
  if (f.kind != Kind::kString || !f.isArray()) return false;
  const std::string& n = f.name;
  return n == "name" || n == "names" || (n.size() > 6 && n.compare(n.size() - 6, 6, "_names") == 0);
}

// Message type at each depth of a resolved path: depth 0 is the root, depth k + 1 the message
// hop k leads into (only meaningful for hops into messages).
std::vector<std::size_t> levelTypes(const MessageSchema& schema, const std::vector<Hop>& hops) {
  std::vector<std::size_t> levels{0};
  for (const Hop& h : hops) levels.push_back(schema.type(h.type).fields[h.field].message);
  return levels;
}

// The nearest key array of the array field reached by `hops`: its depth and field, or false.
bool findKeyArray(const MessageSchema& schema, const std::vector<Hop>& hops, std::size_t* level,
                  std::size_t* field) {
  const std::vector<std::size_t> levels = levelTypes(schema, hops);
  for (std::size_t l = hops.size(); l-- > 0;) {
    const MessageType& t = schema.type(levels[l]);
    for (std::size_t f = 0; f < t.fields.size(); ++f) {
      if (isKeyArray(t.fields[f])) {
        *level = l;
        *field = f;
        return true;
      }
    }
  }
  return false;
}

bool findXyz(const MessageType& t, std::array<std::size_t, 3>* fields) {
  const char* names[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    const int f = t.fieldIndex(names[k]);
    if (f < 0 || t.fields[f].isArray() || !isNumeric(t.fields[f].kind)) return false;
    (*fields)[k] = static_cast<std::size_t>(f);
  }
  return true;
}

[[noreturn]] void unknown(const std::vector<std::string>& path, const std::string& reason) {
  throw UnknownField("no field '" + join(path, path.size()) + "': " + reason);
}

// "field=value" after an array of messages: the first element whose scalar field equals value.
void selectByValue(const MessageSchema& schema, const FieldDefinition& array,
                   const std::vector<std::string>& path, std::size_t i, Hop& hop) {
  const std::string& selector = path[i];
  const MessageType& element = schema.type(array.message);
  const auto equals = selector.find('=');
  const std::string name = "'" + join(path, i) + "'";
  if (equals == std::string::npos) {
    unknown(path, name + " is an array of " + array.type_name +
                      ": index it with a number, *, or <field>=<value> (e.g. id=3)");
  }
  const int f = element.fieldIndex(selector.substr(0, equals));
  if (f < 0 || element.fields[f].isArray() || element.fields[f].kind == Kind::kMessage) {
    unknown(path, "'" + selector.substr(0, equals) + "' is no number or string field of " +
                      element.name + " (it has " + fieldNames(element) + ")");
  }
  const std::string value = selector.substr(equals + 1);
  if (element.fields[f].kind != Kind::kString) {
    try {
      std::size_t used = 0;
      std::stod(value, &used);
      if (used != value.size()) throw std::invalid_argument(value);
    } catch (const std::exception&) {
      unknown(path, "'" + value + "' is not a number, as " + element.name + "'s " +
                        element.fields[f].name + " is");
    }
  }
  hop.match_field = f;
  hop.match_value = value;
}

Resolved resolve(const MessageSchema& schema, const std::vector<std::string>& path) {
  Resolved r;
  std::size_t type = 0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const MessageType& t = schema.type(type);
    const std::string here = i == 0 ? t.name : "'" + join(path, i) + "' (" + t.name + ")";
    const int f = t.fieldIndex(path[i]);
    if (f < 0) {
      if (path[i] == "norm" && i + 1 == path.size() && findXyz(t, &r.norm)) {
        r.end = End::kNorm;
        r.message_type = type;
        return r;
      }
      std::array<std::size_t, 3> xyz;
      unknown(path, here + " has no field '" + path[i] + "' (it has " + fieldNames(t) +
                        (findXyz(t, &xyz) ? ", norm" : "") + ")");
    }
    const FieldDefinition& fd = t.fields[f];
    r.hops.push_back({type, static_cast<std::size_t>(f), -1});
    const std::string name = "'" + join(path, i + 1) + "'";
    if (!fd.isArray()) {
      if (fd.kind == Kind::kMessage) {
        type = fd.message;
        continue;
      }
      if (i + 1 != path.size())
        unknown(path, name + " is a " + fd.type_name + ", it has no fields");
      r.end = fd.kind == Kind::kString ? End::kString : End::kNumber;
      return r;
    }
    if (i + 1 == path.size()) {
      r.end = End::kArray;
      return r;
    }
    const std::string& index = path[++i];
    if (index == "*") unknown(path, "'*' is only expanded in the fields of a configuration");
    if (isIndex(index)) {
      const unsigned long long value = std::stoull(index);
      if (value > std::numeric_limits<std::uint32_t>::max() ||
          (fd.array_length >= 0 && value >= static_cast<unsigned long long>(fd.array_length))) {
        unknown(path, name + " has " +
                          (fd.array_length >= 0 ? std::to_string(fd.array_length) : "fewer") +
                          " elements");
      }
      if (fd.kind == Kind::kMessage) {
        r.hops.back().element = static_cast<long>(value);
        type = fd.message;
        continue;
      }
      if (i + 1 != path.size())
        unknown(path, name + " holds " + fd.type_name + ", it has no fields");
      r.end = End::kElement;
      r.index = static_cast<std::uint32_t>(value);
      return r;
    }
    if (fd.kind == Kind::kMessage) {
      selectByValue(schema, fd, path, i, r.hops.back());
      type = fd.message;
      continue;
    }
    if (fd.array_length != kVariableLength) {
      unknown(path, name + " is an array of " + fd.type_name + "[" +
                        std::to_string(fd.array_length) + "]: index it with a number or *");
    }
    if (!findKeyArray(schema, r.hops, &r.key_level, &r.key_field)) {
      unknown(path, name + " is an array of " + fd.type_name +
                        " without a string[] name/names/*_names to look '" + index +
                        "' up in: index it with a number or *");
    }
    if (i + 1 != path.size()) unknown(path, name + " holds " + fd.type_name + ", it has no fields");
    r.end = End::kKey;
    r.key = index;
    return r;
  }
  r.end = End::kMessage;
  r.message_type = type;
  return r;
}

const FieldDefinition& lastField(const MessageSchema& schema, const Resolved& r) {
  return schema.type(r.hops.back().type).fields[r.hops.back().field];
}

// Numbers only: the ends a FieldReader output may have.
void requireNumeric(const MessageSchema& schema, const Resolved& r,
                    const std::vector<std::string>& path) {
  const std::string name = "'" + join(path, path.size()) + "'";
  switch (r.end) {
    case End::kNumber:
    case End::kKey:
    case End::kNorm:
      return;
    case End::kElement:
      if (lastField(schema, r).kind != Kind::kString) return;
      unknown(path, name + " is a string, not a number");
    case End::kString:
      unknown(path, name + " is a string, not a number");
    case End::kArray:
      unknown(path, name + " is an array of " + lastField(schema, r).type_name +
                        ": add an index, a name or *");
    case End::kMessage: {
      const MessageType& t = schema.type(r.message_type);
      unknown(path,
              (path.empty() ? t.name : name + " is a " + t.name) + " with fields " + fieldNames(t));
    }
  }
}

// The path (as components) of the message at depth `level` of r, e.g. {"objects", "0"}.
std::vector<std::string> pathToLevel(const MessageSchema& schema, const Resolved& r,
                                     std::size_t level) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < level; ++k) {
    const Hop& h = r.hops[k];
    out.push_back(schema.type(h.type).fields[h.field].name);
    if (h.element >= 0) out.push_back(std::to_string(h.element));
    if (h.match_field >= 0) {
      const MessageType& element = schema.type(schema.type(h.type).fields[h.field].message);
      out.push_back(element.fields[h.match_field].name + "=" + h.match_value);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Bounds-checked walking.

class Cursor {
 public:
  Cursor(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  // `count` items of `item` bytes each; the product is checked before it is formed.
  const std::uint8_t* take(std::size_t count, std::size_t item, const FieldDefinition& f,
                           const MessageType& owner) {
    if (item != 0 && count > (size_ - pos_) / item) fail(count, item, f, owner);
    const std::uint8_t* p = data_ + pos_;
    pos_ += count * item;
    return p;
  }
  std::uint32_t length(const FieldDefinition& f, const MessageType& owner) {
    std::uint32_t n;
    std::memcpy(&n, take(1, 4, f, owner), 4);
    return n;
  }
  std::size_t remaining() const { return size_ - pos_; }
  std::size_t position() const { return pos_; }
  // Back to a position this cursor has already passed (to walk an element again).
  void rewind(std::size_t pos) { pos_ = std::min(pos, pos_); }
  std::size_t size() const { return size_; }

 private:
  [[noreturn]] void fail(std::size_t count, std::size_t item, const FieldDefinition& f,
                         const MessageType& owner) const {
    throw MessageError("message truncated or corrupt: field '" + f.name + "' of " + owner.name +
                       " needs " + std::to_string(count) + " x " + std::to_string(item) +
                       " bytes at byte " + std::to_string(pos_) + " of " + std::to_string(size_));
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

template <typename T>
double load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

// Same arithmetic as ros::Time::toSec(), so stamps match the typed reader's bit for bit.
template <typename T>
double loadTime(const std::uint8_t* p) {
  T sec, nsec;
  std::memcpy(&sec, p, 4);
  std::memcpy(&nsec, p + 4, 4);
  return static_cast<double>(sec) + 1e-9 * static_cast<double>(nsec);
}

double toDouble(Kind kind, const std::uint8_t* p) {
  switch (kind) {
    case Kind::kBool:
      return p[0] != 0 ? 1.0 : 0.0;
    case Kind::kInt8:
      return load<std::int8_t>(p);
    case Kind::kUint8:
      return load<std::uint8_t>(p);
    case Kind::kInt16:
      return load<std::int16_t>(p);
    case Kind::kUint16:
      return load<std::uint16_t>(p);
    case Kind::kInt32:
      return load<std::int32_t>(p);
    case Kind::kUint32:
      return load<std::uint32_t>(p);
    case Kind::kInt64:
      return load<std::int64_t>(p);
    case Kind::kUint64:
      return load<std::uint64_t>(p);
    case Kind::kFloat32:
      return load<float>(p);
    case Kind::kFloat64:
      return load<double>(p);
    case Kind::kTime:
      return loadTime<std::uint32_t>(p);
    case Kind::kDuration:
      return loadTime<std::int32_t>(p);
    case Kind::kString:
    case Kind::kMessage:
      break;
  }
  return 0.0;
}

// What to do with the fields of one message instance; a null action skips the field.
struct PlanNode;
// An element of an array of messages chosen by the value of one of its fields.
struct Selector {
  int field = -1;  // in the element type
  std::string text;
  double number = 0;
  int key_slot = -1;  // scalars (numbers) or strings slot of the probed field
  std::unique_ptr<PlanNode> plan;
};
struct FieldAction {
  int scalar_slot = -1;             // numeric scalar -> scalars
  int array_slot = -1;              // array -> arrays (data pointer and count)
  int strings_slot = -1;            // string or string[] -> strings
  std::unique_ptr<PlanNode> child;  // nested message
  std::vector<std::pair<std::uint32_t, std::unique_ptr<PlanNode>>> elements;  // sorted
  std::vector<Selector> selectors;
  std::unique_ptr<PlanNode> probe;  // reads the selectors' fields of every element
};
struct PlanNode {
  std::vector<std::unique_ptr<FieldAction>> actions;  // one per field of the type
};

struct ArrayCapture {
  const std::uint8_t* data = nullptr;
  std::uint32_t count = 0;
  bool set = false;
};

struct Output {
  End end = End::kNumber;
  Kind kind = Kind::kFloat64;  // element kind of kElement / kKey
  int slot = -1;               // scalar slot (kNumber) or array slot (kElement, kKey, kArray)
  std::uint32_t index = 0;
  std::string key;
  int key_slot = -1;  // strings slot of the key array
  std::array<int, 3> norm{-1, -1, -1};
  mutable std::uint32_t key_guess = 0;  // where the key was in the last message
};

// A compiled set of reads over one schema: a tree of the fields to visit, slots for what they
// hold, and the outputs computed from the slots after each walk.
class Plan {
 public:
  explicit Plan(const MessageSchema& schema) : schema_(schema), root_(node(0)) {}

  std::size_t add(const Resolved& r) {
    Output out;
    out.end = r.end;
    switch (r.end) {
      case End::kNumber:
        out.slot = slot(action(r)->scalar_slot, scalars_);
        break;
      case End::kElement:
      case End::kKey:
      case End::kArray:
        out.kind = lastField(schema_, r).kind;
        out.slot = slot(action(r)->array_slot, arrays_);
        out.index = r.index;
        out.key = r.key;
        if (r.end == End::kKey) {
          const std::size_t type = levelTypes(schema_, r.hops)[r.key_level];
          out.key_slot =
              slot(ensure(nodeAt(r, r.key_level), type, r.key_field)->strings_slot, strings_);
        }
        break;
      case End::kString:
        out.slot = slot(action(r)->strings_slot, strings_);
        break;
      case End::kNorm: {
        PlanNode* n = nodeAt(r, r.hops.size());
        for (int k = 0; k < 3; ++k)
          out.norm[k] = slot(ensure(n, r.message_type, r.norm[k])->scalar_slot, scalars_);
        break;
      }
      case End::kMessage:
        throw UnknownField("a message is not a value");
    }
    outputs_.push_back(std::move(out));
    return outputs_.size() - 1;
  }

  void run(const std::uint8_t* data, std::size_t size) {
    scalar_set_.assign(scalars_.size(), 0);
    for (ArrayCapture& a : arrays_) a.set = false;
    for (auto& s : strings_) s.clear();
    strings_set_.assign(strings_.size(), 0);
    Cursor c(data, size);
    walk(root_.get(), schema_.root(), c);
    if (c.remaining() != 0) {
      throw MessageError("message of " + std::to_string(size) + " bytes has " +
                         std::to_string(c.remaining()) + " bytes after the end of its " +
                         schema_.root().name + " definition (wrong definition or corrupt)");
    }
  }

  // Value of output k after run(); false when the message does not carry it.
  bool value(std::size_t k, double* v) const {
    const Output& o = outputs_[k];
    switch (o.end) {
      case End::kNumber:
        *v = scalars_[o.slot];
        return scalar_set_[o.slot];
      case End::kNorm: {
        for (int s : o.norm)
          if (!scalar_set_[s]) return false;
        const double x = scalars_[o.norm[0]], y = scalars_[o.norm[1]], z = scalars_[o.norm[2]];
        *v = std::sqrt(x * x + y * y + z * z);
        return true;
      }
      case End::kArray:
        *v = arrays_[o.slot].count;
        return arrays_[o.slot].set;
      case End::kElement:
        return element(arrays_[o.slot], o.kind, o.index, v);
      case End::kKey: {
        if (!strings_set_[o.key_slot]) return false;
        const std::vector<std::string_view>& keys = strings_[o.key_slot];
        if (o.key_guess >= keys.size() || keys[o.key_guess] != o.key) {
          const auto it = std::find(keys.begin(), keys.end(), o.key);
          if (it == keys.end()) return false;
          o.key_guess = static_cast<std::uint32_t>(it - keys.begin());
        }
        return element(arrays_[o.slot], o.kind, o.key_guess, v);
      }
      case End::kString:
      case End::kMessage:
        break;
    }
    return false;
  }

  const std::vector<std::string_view>* strings(std::size_t k) const {
    const Output& o = outputs_[k];
    return strings_set_[o.slot] ? &strings_[o.slot] : nullptr;
  }

 private:
  std::unique_ptr<PlanNode> node(std::size_t type) const {
    auto n = std::make_unique<PlanNode>();
    n->actions.resize(schema_.type(type).fields.size());
    return n;
  }
  FieldAction* ensure(PlanNode* n, std::size_t, std::size_t field) {
    if (!n->actions[field]) n->actions[field] = std::make_unique<FieldAction>();
    return n->actions[field].get();
  }
  // The node of the message at depth `level` (creating the way there).
  PlanNode* nodeAt(const Resolved& r, std::size_t level) {
    PlanNode* n = root_.get();
    for (std::size_t k = 0; k < level; ++k) {
      const Hop& h = r.hops[k];
      FieldAction* a = ensure(n, h.type, h.field);
      const std::size_t type = schema_.type(h.type).fields[h.field].message;
      if (h.match_field >= 0) {
        n = selector(a, type, h);
        continue;
      }
      if (h.element < 0) {
        if (!a->child) a->child = node(type);
        n = a->child.get();
        continue;
      }
      const auto index = static_cast<std::uint32_t>(h.element);
      auto it = std::lower_bound(a->elements.begin(), a->elements.end(), index,
                                 [](const auto& e, std::uint32_t i) { return e.first < i; });
      if (it == a->elements.end() || it->first != index)
        it = a->elements.emplace(it, index, node(type));
      n = it->second.get();
    }
    return n;
  }
  PlanNode* selector(FieldAction* a, std::size_t type, const Hop& h) {
    for (Selector& s : a->selectors)
      if (s.field == h.match_field && s.text == h.match_value) return s.plan.get();
    if (!a->probe) a->probe = node(type);
    Selector s;
    s.field = h.match_field;
    s.text = h.match_value;
    FieldAction* key = ensure(a->probe.get(), type, static_cast<std::size_t>(h.match_field));
    if (schema_.type(type).fields[h.match_field].kind == Kind::kString) {
      s.key_slot = slot(key->strings_slot, strings_);
    } else {
      s.number = std::stod(h.match_value);
      s.key_slot = slot(key->scalar_slot, scalars_);
    }
    s.plan = node(type);
    a->selectors.push_back(std::move(s));
    return a->selectors.back().plan.get();
  }
  FieldAction* action(const Resolved& r) {
    return ensure(nodeAt(r, r.hops.size() - 1), r.hops.back().type, r.hops.back().field);
  }
  template <typename Slots>
  static int slot(int& existing, Slots& slots) {
    if (existing < 0) {
      existing = static_cast<int>(slots.size());
      slots.emplace_back();
    }
    return existing;
  }
  static bool element(const ArrayCapture& a, Kind kind, std::uint32_t index, double* v) {
    if (!a.set || index >= a.count) return false;
    *v = toDouble(kind, a.data + static_cast<std::size_t>(index) * builtinSize(kind));
    return true;
  }

  std::size_t elementMin(const FieldDefinition& f) const {
    if (f.kind == Kind::kMessage) return schema_.type(f.message).min_size;
    return f.kind == Kind::kString ? 4 : builtinSize(f.kind);
  }

  void walk(const PlanNode* n, const MessageType& type, Cursor& c) {
    if (!n && type.fixed_size) {
      if (*type.fixed_size != 0) c.take(1, *type.fixed_size, type.fields.front(), type);
      return;
    }
    for (std::size_t f = 0; f < type.fields.size(); ++f) {
      const FieldAction* a = n ? n->actions[f].get() : nullptr;
      if (a) {
        visit(type.fields[f], *a, type, c);
      } else {
        skip(type.fields[f], type, c);
      }
    }
  }

  void readString(const FieldDefinition& f, const MessageType& owner, Cursor& c, int slot) {
    const std::uint32_t n = c.length(f, owner);
    const std::uint8_t* p = c.take(n, 1, f, owner);
    if (slot >= 0) {
      strings_[slot].emplace_back(reinterpret_cast<const char*>(p), n);
      strings_set_[slot] = 1;
    }
  }

  void visit(const FieldDefinition& f, const FieldAction& a, const MessageType& owner, Cursor& c) {
    if (!f.isArray()) {
      if (f.kind == Kind::kMessage) {
        walk(a.child.get(), schema_.type(f.message), c);
      } else if (f.kind == Kind::kString) {
        readString(f, owner, c, a.strings_slot);
      } else {
        const std::uint8_t* p = c.take(1, builtinSize(f.kind), f, owner);
        if (a.scalar_slot >= 0) {
          scalars_[a.scalar_slot] = toDouble(f.kind, p);
          scalar_set_[a.scalar_slot] = 1;
        }
      }
      return;
    }
    const std::uint32_t count = arrayCount(f, owner, c);
    if (a.array_slot >= 0) arrays_[a.array_slot] = {nullptr, count, true};
    if (f.kind == Kind::kString) {
      if (a.strings_slot >= 0) strings_set_[a.strings_slot] = 1;
      for (std::uint32_t k = 0; k < count; ++k) readString(f, owner, c, a.strings_slot);
    } else if (f.kind != Kind::kMessage) {
      const std::uint8_t* p = c.take(count, builtinSize(f.kind), f, owner);
      if (a.array_slot >= 0) arrays_[a.array_slot].data = p;
    } else {
      visitElements(f, a, owner, count, c);
    }
  }

  void visitElements(const FieldDefinition& f, const FieldAction& a, const MessageType& owner,
                     std::uint32_t count, Cursor& c) {
    const MessageType& type = schema_.type(f.message);
    if (!a.selectors.empty()) return visitSelected(type, a, count, c);
    std::uint32_t next = 0;  // first element not yet consumed
    for (const auto& [index, plan] : a.elements) {
      if (index >= count) break;
      skipElements(f, type, owner, index - next, c);
      walk(plan.get(), type, c);
      next = index + 1;
    }
    skipElements(f, type, owner, count - std::min(next, count), c);
  }

  // Every element is probed for the selectors' fields, then walked again by the plan of its
  // index and of each selector it is the first match of.
  void visitSelected(const MessageType& type, const FieldAction& a, std::uint32_t count,
                     Cursor& c) {
    std::vector<char> matched(a.selectors.size(), 0);
    auto element_plan = a.elements.begin();
    for (std::uint32_t k = 0; k < count; ++k) {
      for (const Selector& s : a.selectors) {  // the probe reads this element's keys only
        if (type.fields[s.field].kind == Kind::kString) {
          strings_[s.key_slot].clear();
          strings_set_[s.key_slot] = 0;
        } else {
          scalar_set_[s.key_slot] = 0;
        }
      }
      const std::size_t start = c.position();
      walk(a.probe.get(), type, c);  // every walk of one element ends at the same byte
      while (element_plan != a.elements.end() && element_plan->first < k) ++element_plan;
      if (element_plan != a.elements.end() && element_plan->first == k) {
        c.rewind(start);
        walk(element_plan->second.get(), type, c);
      }
      for (std::size_t j = 0; j < a.selectors.size(); ++j) {
        if (matched[j] || !selected(type, a.selectors[j])) continue;
        matched[j] = 1;
        c.rewind(start);
        walk(a.selectors[j].plan.get(), type, c);
      }
    }
  }

  bool selected(const MessageType& type, const Selector& s) const {
    if (type.fields[s.field].kind == Kind::kString) {
      const auto& v = strings_[s.key_slot];
      return strings_set_[s.key_slot] && v.size() == 1 && v[0] == s.text;
    }
    return scalar_set_[s.key_slot] && scalars_[s.key_slot] == s.number;
  }

  void skipElements(const FieldDefinition& f, const MessageType& type, const MessageType& owner,
                    std::uint32_t count, Cursor& c) {
    if (type.fixed_size) {
      c.take(count, *type.fixed_size, f, owner);
      return;
    }
    for (std::uint32_t k = 0; k < count; ++k) walk(nullptr, type, c);
  }

  std::uint32_t arrayCount(const FieldDefinition& f, const MessageType& owner, Cursor& c) {
    if (f.array_length >= 0) return static_cast<std::uint32_t>(f.array_length);
    const std::uint32_t count = c.length(f, owner);
    // Every element takes at least element_min bytes: a corrupt count fails here, before any
    // loop trusts it.
    const std::size_t min = elementMin(f);
    if (min != 0 && count > c.remaining() / min) {
      throw MessageError("message truncated or corrupt: array '" + f.name + "' of " + owner.name +
                         " claims " + std::to_string(count) + " elements, only " +
                         std::to_string(c.remaining()) + " bytes are left");
    }
    return count;
  }

  void skip(const FieldDefinition& f, const MessageType& owner, Cursor& c) {
    if (!f.isArray()) {
      if (f.kind == Kind::kMessage) {
        walk(nullptr, schema_.type(f.message), c);
      } else if (f.kind == Kind::kString) {
        c.take(c.length(f, owner), 1, f, owner);
      } else {
        c.take(1, builtinSize(f.kind), f, owner);
      }
      return;
    }
    const std::uint32_t count = arrayCount(f, owner, c);
    if (f.kind == Kind::kMessage) {
      skipElements(f, schema_.type(f.message), owner, count, c);
    } else if (f.kind == Kind::kString) {
      for (std::uint32_t k = 0; k < count; ++k) c.take(c.length(f, owner), 1, f, owner);
    } else {
      c.take(count, builtinSize(f.kind), f, owner);
    }
  }

  MessageSchema schema_;
  std::unique_ptr<PlanNode> root_;
  std::vector<Output> outputs_;
  std::vector<double> scalars_;
  std::vector<char> scalar_set_;
  std::vector<ArrayCapture> arrays_;
  std::vector<std::vector<std::string_view>> strings_;
  std::vector<char> strings_set_;
};

}  // namespace

std::vector<std::string> splitPath(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t begin = path.rfind('/', 0) == 0 ? 1 : 0;
  if (begin >= path.size()) throw UnknownField("empty field path '" + path + "'");
  while (true) {
    const std::size_t end = path.find('/', begin);
    const std::string part = path.substr(begin, end == std::string::npos ? end : end - begin);
    if (part.empty()) throw UnknownField("empty component in field path '" + path + "'");
    parts.push_back(part);
    if (end == std::string::npos) return parts;
    begin = end + 1;
  }
}

// ---------------------------------------------------------------------------------------------
// FieldReader

struct FieldReader::Impl {
  explicit Impl(const MessageSchema& schema) : plan(schema) {}
  Plan plan;
  std::vector<std::size_t> outputs;
  long stamp_output = -1;
  std::vector<double> values;
  std::vector<char> present;
  double stamp = 0;
};

FieldReader::FieldReader(const MessageSchema& schema, const std::vector<std::string>& paths)
    : impl_(std::make_unique<Impl>(schema)) {
  for (const std::string& path : paths) {
    const std::vector<std::string> parts = splitPath(path);
    const Resolved r = resolve(schema, parts);
    requireNumeric(schema, r, parts);
    impl_->outputs.push_back(impl_->plan.add(r));
  }
  const int header = schema.root().fieldIndex("header");
  if (header >= 0 && schema.root().fields[header].type_name == "std_msgs/Header" &&
      !schema.root().fields[header].isArray()) {
    const MessageType& h = schema.type(schema.root().fields[header].message);
    const int stamp = h.fieldIndex("stamp");
    if (stamp >= 0 && h.fields[stamp].kind == Kind::kTime && !h.fields[stamp].isArray())
      impl_->stamp_output =
          static_cast<long>(impl_->plan.add(resolve(schema, {"header", "stamp"})));
  }
  impl_->values.resize(paths.size());
  impl_->present.resize(paths.size());
}

FieldReader::~FieldReader() = default;
FieldReader::FieldReader(FieldReader&&) noexcept = default;
FieldReader& FieldReader::operator=(FieldReader&&) noexcept = default;

void FieldReader::read(const std::uint8_t* data, std::size_t size) {
  Impl& m = *impl_;
  m.plan.run(data, size);
  for (std::size_t k = 0; k < m.outputs.size(); ++k)
    m.present[k] = m.plan.value(m.outputs[k], &m.values[k]);
  m.stamp = 0;
  if (m.stamp_output >= 0 && !m.plan.value(static_cast<std::size_t>(m.stamp_output), &m.stamp))
    m.stamp = 0;
}

std::size_t FieldReader::size() const {
  return impl_->outputs.size();
}
bool FieldReader::present(std::size_t k) const {
  return impl_->present.at(k);
}
double FieldReader::value(std::size_t k) const {
  return impl_->values.at(k);
}
double FieldReader::headerStamp() const {
  return impl_->stamp;
}

// ---------------------------------------------------------------------------------------------
// Sample queries, expansion and listing

namespace {

// Runs one query on a sample message; the output of `r` after the walk.
std::size_t lengthOf(const MessageSchema& schema, const std::uint8_t* sample, std::size_t size,
                     const Resolved& r) {
  Plan plan(schema);
  const std::size_t k = plan.add(r);
  plan.run(sample, size);
  double v = 0;
  return plan.value(k, &v) ? static_cast<std::size_t>(v) : 0;
}

std::vector<std::string> stringsOf(const MessageSchema& schema, const std::uint8_t* sample,
                                   std::size_t size, const Resolved& r) {
  Plan plan(schema);
  Resolved q = r;
  q.end = End::kString;
  const std::size_t k = plan.add(q);
  plan.run(sample, size);
  std::vector<std::string> out;
  if (const auto* s = plan.strings(k)) out.assign(s->begin(), s->end());
  return out;
}

// The key array of the array reached by r (resolved as a whole array), as a path.
bool keyPath(const MessageSchema& schema, const Resolved& r, std::vector<std::string>* path) {
  std::size_t level = 0, field = 0;
  const FieldDefinition& array = lastField(schema, r);
  if (array.kind == Kind::kMessage || array.kind == Kind::kString ||
      array.array_length != kVariableLength || !findKeyArray(schema, r.hops, &level, &field))
    return false;
  *path = pathToLevel(schema, r, level);
  path->push_back(schema.type(levelTypes(schema, r.hops)[level]).fields[field].name);
  return true;
}

// The names that index the array reached by r in the sample: its key array's strings when they
// are as many as the array's elements (a key array of another length describes something else).
std::vector<std::string> keyNames(const MessageSchema& schema, const std::uint8_t* sample,
                                  std::size_t size, const Resolved& r) {
  std::vector<std::string> keys;
  if (!keyPath(schema, r, &keys)) return {};
  std::vector<std::string> names = stringsOf(schema, sample, size, resolve(schema, keys));
  if (names.size() != lengthOf(schema, sample, size, r)) return {};
  return names;
}

void expand(const MessageSchema& schema, const std::uint8_t* sample, std::size_t size,
            const std::vector<std::string>& parts, std::vector<std::string>& out) {
  const auto star = std::find(parts.begin(), parts.end(), "*");
  if (star == parts.end()) {
    requireNumeric(schema, resolve(schema, parts), parts);
    out.push_back(join(parts, parts.size()));
    return;
  }
  const std::vector<std::string> prefix(parts.begin(), star);
  const Resolved r = resolve(schema, prefix);
  if (r.end != End::kArray) unknown(parts, "'*' must follow an array");
  std::vector<std::string> names = keyNames(schema, sample, size, r);
  if (names.empty()) {
    const std::size_t n = lengthOf(schema, sample, size, r);
    for (std::size_t k = 0; k < n; ++k) names.push_back(std::to_string(k));
  }
  for (const std::string& name : names) {
    std::vector<std::string> concrete = prefix;
    concrete.push_back(name);
    concrete.insert(concrete.end(), star + 1, parts.end());
    expand(schema, sample, size, concrete, out);
  }
}

std::string range(std::size_t n) {
  return n == 0 ? "<empty>" : "<0.." + std::to_string(n - 1) + ">";
}

void listFields(const MessageSchema& schema, const std::uint8_t* sample, std::size_t size,
                std::size_t type, const std::vector<std::string>& path, const std::string& shown,
                std::size_t max_names, std::vector<std::string>& out) {
  const MessageType& t = schema.type(type);
  for (const FieldDefinition& f : t.fields) {
    std::vector<std::string> p = path;
    p.push_back(f.name);
    const std::string name = shown + f.name;
    if (!f.isArray()) {
      if (f.kind == Kind::kMessage) {
        listFields(schema, sample, size, f.message, p, name + "/", max_names, out);
      } else if (f.kind != Kind::kString) {
        out.push_back(name);
      }
      continue;
    }
    if (f.kind == Kind::kString) continue;
    const Resolved r = resolve(schema, p);
    const std::size_t n = lengthOf(schema, sample, size, r);
    if (f.kind == Kind::kMessage) {
      if (n == 0) {
        out.push_back(name + "/<empty> (array of " + f.type_name + ")");
      } else {
        p.push_back("0");
        listFields(schema, sample, size, f.message, p, name + "/" + range(n) + "/", max_names, out);
      }
      continue;
    }
    std::string entry = name + "/" + range(n);
    const std::vector<std::string> names = keyNames(schema, sample, size, r);
    if (!names.empty()) {
      entry += " or <name: ";
      for (std::size_t k = 0; k < names.size() && k < max_names; ++k)
        entry += (k ? ", " : "") + names[k];
      if (names.size() > max_names) entry += ", ... (" + std::to_string(names.size()) + " names)";
      entry += ">";
    }
    out.push_back(entry);
  }
  std::array<std::size_t, 3> xyz;
  if (findXyz(t, &xyz) && t.fieldIndex("norm") < 0) out.push_back(shown + "norm");
}

}  // namespace

std::vector<std::string> expandFields(const MessageSchema& schema, const std::uint8_t* sample,
                                      std::size_t size, const std::vector<std::string>& patterns) {
  std::vector<std::string> out;
  for (const std::string& pattern : patterns) {
    try {
      expand(schema, sample, size, splitPath(pattern), out);
    } catch (const UnknownField& e) {
      std::string fields;
      for (const std::string& f : listNumericFields(schema, sample, size)) fields += "\n  " + f;
      throw UnknownField(std::string(e.what()) + "\nnumeric fields of " + schema.root().name +
                         " (first message):" + fields);
    }
  }
  return out;
}

std::vector<std::string> listNumericFields(const MessageSchema& schema, const std::uint8_t* sample,
                                           std::size_t size, std::size_t max_names) {
  std::vector<std::string> out;
  listFields(schema, sample, size, 0, {}, "", max_names, out);
  return out;
}

std::size_t arrayLength(const MessageSchema& schema, const std::uint8_t* sample, std::size_t size,
                        const std::string& path) {
  const std::vector<std::string> parts = splitPath(path);
  const Resolved r = resolve(schema, parts);
  if (r.end != End::kArray) unknown(parts, "'" + path + "' is not an array");
  return lengthOf(schema, sample, size, r);
}

std::vector<std::string> stringValues(const MessageSchema& schema, const std::uint8_t* sample,
                                      std::size_t size, const std::string& path) {
  const std::vector<std::string> parts = splitPath(path);
  const Resolved r = resolve(schema, parts);
  if (r.end != End::kString &&
      !(r.end == End::kArray && lastField(schema, r).kind == Kind::kString))
    unknown(parts, "'" + path + "' is not a string or string[]");
  return stringsOf(schema, sample, size, r);
}

}  // namespace lfd::rosmsg
