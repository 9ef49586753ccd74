// JSON field readers of the library formats (skill library, sensory signature): each names the
// JSON location of what is wrong ("segments[0].demos[1].dmp.tau: ..."). Internal to lfd_dmp.
#pragma once

#include <nlohmann/json.hpp>

#include <Eigen/Core>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace lfd_dmp {
namespace json_fields {

using nlohmann::json;

[[noreturn]] inline void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

inline json vectorJson(const Eigen::VectorXd& v) {
  return json(std::vector<double>(v.data(), v.data() + v.size()));
}

inline const json& member(const json& j, const char* key, const std::string& where) {
  if (!j.is_object()) fail(where, "expected an object");
  const auto it = j.find(key);
  if (it == j.end()) fail(where, std::string("missing field \"") + key + "\"");
  return *it;
}

inline double number(const json& j, const std::string& where) {
  if (!j.is_number()) fail(where, "expected a number, got " + std::string(j.type_name()));
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(where, "number is not finite");
  return v;
}

inline std::string text(const json& j, const std::string& where) {
  if (!j.is_string()) fail(where, "expected a string, got " + std::string(j.type_name()));
  return j.get<std::string>();
}

inline Eigen::VectorXd vector(const json& j, const std::string& where, long expected = -1) {
  if (!j.is_array()) fail(where, "expected an array of numbers, got " + std::string(j.type_name()));
  if (expected >= 0 && static_cast<long>(j.size()) != expected) {
    fail(where,
         "expected " + std::to_string(expected) + " numbers, got " + std::to_string(j.size()));
  }
  Eigen::VectorXd v(static_cast<Eigen::Index>(j.size()));
  for (size_t i = 0; i < j.size(); ++i)
    v[static_cast<Eigen::Index>(i)] = number(j[i], where + "[" + std::to_string(i) + "]");
  return v;
}

inline std::vector<std::string> texts(const json& j, const std::string& where) {
  if (!j.is_array()) fail(where, "expected an array of strings");
  std::vector<std::string> out;
  for (size_t i = 0; i < j.size(); ++i)
    out.push_back(text(j[i], where + "[" + std::to_string(i) + "]"));
  return out;
}

}  // namespace json_fields
}  // namespace lfd_dmp
