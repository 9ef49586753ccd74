// A walk over every field of one serialized message: the strings it holds (a request's budget)
// and whether the bytes fit the definition at all (a bag whose bytes do not match its declared
// type). Fixed-size parts are skipped in one step, so a message of large numeric arrays costs
// little.
#include <algorithm>
#include <cstring>
#include <string>
#include <string_view>

#include "lfd_core/io/ros_message_reader.hpp"

namespace lfd::rosmsg {
namespace {

class Walk {
 public:
  Walk(const MessageSchema& schema, const std::uint8_t* data, std::size_t size,
       const StringVisitor& visit)
      : schema_(schema), data_(data), size_(size), visit_(visit) {}

  void message(const MessageType& type, const std::string& prefix) {
    if (type.fixed_size) {  // nothing variable inside: no string, one bounds check
      take(*type.fixed_size, 1, prefix.empty() ? type.name : prefix);
      return;
    }
    for (const FieldDefinition& f : type.fields) {
      const std::string path = prefix.empty() ? f.name : prefix + "." + f.name;
      if (!f.isArray()) {
        value(f, path);
        continue;
      }
      const std::uint32_t count = f.array_length == kVariableLength
                                      ? length(path)
                                      : static_cast<std::uint32_t>(f.array_length);
      elements(f, count, path);
    }
  }

  void finish(const std::string& type) const {
    if (pos_ != size_) {
      throw MessageError("message of " + std::to_string(size_) + " bytes has " +
                         std::to_string(size_ - pos_) + " bytes after the end of its " + type +
                         " definition");
    }
  }

 private:
  void elements(const FieldDefinition& f, std::uint32_t count, const std::string& path) {
    const std::size_t fixed = f.kind == Kind::kMessage
                                  ? schema_.type(f.message).fixed_size.value_or(0)
                                  : builtinSize(f.kind);
    if (fixed > 0) {  // numbers, or messages of fixed size: skipped at once
      take(count, fixed, path);
      return;
    }
    // Each element takes at least 4 bytes (a string's length, or a message's smallest size):
    // a corrupt count is refused before it is walked.
    const std::size_t least =
        f.kind == Kind::kMessage ? std::max<std::size_t>(schema_.type(f.message).min_size, 1) : 4;
    if (count > (size_ - pos_) / least) fail(path, count, least);
    for (std::uint32_t i = 0; i < count; ++i) value(f, path + "[" + std::to_string(i) + "]");
  }

  void value(const FieldDefinition& f, const std::string& path) {
    if (f.kind == Kind::kMessage) {
      message(schema_.type(f.message), path);
    } else if (f.kind == Kind::kString) {
      const std::uint32_t n = length(path);
      const std::uint8_t* p = take(n, 1, path);
      visit_(path, std::string_view(reinterpret_cast<const char*>(p), n));
    } else {
      take(1, builtinSize(f.kind), path);
    }
  }

  std::uint32_t length(const std::string& path) {
    std::uint32_t n;
    std::memcpy(&n, take(1, 4, path), 4);
    return n;
  }

  const std::uint8_t* take(std::size_t count, std::size_t item, const std::string& path) {
    if (item != 0 && count > (size_ - pos_) / item) fail(path, count, item);
    const std::uint8_t* p = data_ + pos_;
    pos_ += count * item;
    return p;
  }

  [[noreturn]] void fail(const std::string& path, std::size_t count, std::size_t item) const {
    throw MessageError("field '" + path + "' needs " + std::to_string(count) + " x " +
                       std::to_string(item) + " bytes at byte " + std::to_string(pos_) + " of " +
                       std::to_string(size_));
  }

  const MessageSchema& schema_;
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  const StringVisitor& visit_;
};

}  // namespace

void forEachString(const MessageSchema& schema, const std::uint8_t* data, std::size_t size,
                   const StringVisitor& visit) {
  Walk walk(schema, data, size, visit);
  walk.message(schema.root(), "");
  walk.finish(schema.root().name);
}

void checkMessageBytes(const MessageSchema& schema, const std::uint8_t* data, std::size_t size) {
  forEachString(schema, data, size, [](const std::string&, std::string_view) {});
}

}  // namespace lfd::rosmsg
