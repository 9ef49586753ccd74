// The kinds of file lfd writes, each recognised by what lfd puts at its start or top level: an
// existing output is replaced only when it is one (safe_paths.hpp, OutputKind).
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "lfd_core/io/safe_paths.hpp"

namespace lfd {
namespace {

// The first `n` bytes of the file (fewer if it is shorter), read from its open descriptor.
std::string head(const InputFile& file, std::size_t n) {
  std::string bytes(n, '\0');
  std::size_t got = 0;
  while (got < n) {
    const ssize_t r = ::pread(file.fd(), bytes.data() + got, n - got, static_cast<off_t>(got));
    if (r <= 0) break;
    got += static_cast<std::size_t>(r);
  }
  bytes.resize(got);
  return bytes;
}

// Streams a JSON document and notes its top-level members: stops as soon as "format" is known
// (returning false ends the parse), so a large file is never held in memory.
class TopLevelMembers : public nlohmann::json::json_sax_t {
 public:
  using Json = nlohmann::json;
  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(Json::number_integer_t) override { return value(); }
  bool number_unsigned(Json::number_unsigned_t) override { return value(); }
  bool number_float(Json::number_float_t, const Json::string_t&) override { return value(); }
  bool binary(Json::binary_t&) override { return value(); }
  bool string(Json::string_t& s) override {
    if (depth_ == 1 && key_ == "format") {
      format_ = s;
      found_format_ = true;
      return false;  // what decides is known
    }
    return value();
  }
  bool start_object(std::size_t) override { return open(true); }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(false); }
  bool end_array() override { return close(); }
  bool key(Json::string_t& k) override {
    if (depth_ == 1) {
      key_ = k;
      members_.insert(k);
    }
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    valid_ = false;
    return false;
  }

  bool foundFormat() const { return found_format_; }
  const std::string& format() const { return format_; }
  // A whole, valid document whose root is an object.
  bool completeObject() const { return valid_ && root_object_ && depth_ == 0; }
  bool has(const std::string& member) const { return members_.count(member) > 0; }

 private:
  bool value() { return depth_ > 0; }  // a bare value at the root is no object
  bool open(bool object) {
    if (depth_ == 0) {
      if (!object || started_) return false;
      root_object_ = started_ = true;
    }
    ++depth_;
    return true;
  }
  bool close() {
    --depth_;
    return true;
  }

  int depth_ = 0;
  bool started_ = false, root_object_ = false, valid_ = true, found_format_ = false;
  std::string key_, format_;
  std::set<std::string> members_;
};

}  // namespace

OutputKind bagOutput() {
  return {"ROS bag", [](const InputFile& file) {
            static const std::string kVersionLine = "#ROSBAG V2.0\n";
            return head(file, kVersionLine.size()) == kVersionLine;
          }};
}

OutputKind textOutput(const std::string& name, const std::string& first_line) {
  return {name, [first_line](const InputFile& file) {
            const std::string line = first_line + "\n";
            return head(file, line.size()) == line;
          }};
}

OutputKind jsonOutput(const std::string& name, const std::string& format,
                      const std::vector<std::string>& legacy_members) {
  return {name, [format, legacy_members](const InputFile& file) {
            std::ifstream in(file.readPath(), std::ios::binary);
            if (!in) return false;
            TopLevelMembers members;
            nlohmann::json::sax_parse(in, &members);
            if (members.foundFormat()) return members.format() == format;
            // No "format" at all: a file lfd wrote before it had one, by its structure.
            if (legacy_members.empty() || !members.completeObject()) return false;
            for (const std::string& m : legacy_members)
              if (!members.has(m)) return false;
            return true;
          }};
}

}  // namespace lfd
