#include "lfd_dmp/execution_request.hpp"

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

std::string clipped(const std::string& s) {
  return s.size() <= 40 ? s : s.substr(0, 40) + "... (" + std::to_string(s.size()) + " chars)";
}

std::string formatted(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

void checkLimits(const RequestLimits& l) {
  if (!(l.min_duration_scale > 0.0) || !(l.max_duration_scale >= l.min_duration_scale) ||
      !std::isfinite(l.max_duration_scale))
    throw std::invalid_argument("~limits: need 0 < min_duration_scale <= max_duration_scale");
  if (!(l.max_plan_seconds > 0.0) || !std::isfinite(l.max_plan_seconds))
    throw std::invalid_argument("~limits/max_plan_seconds must be finite and > 0");
  if (!(l.quaternion_tolerance >= 0.0) || !(l.quaternion_tolerance < 1.0))
    throw std::invalid_argument("~limits/quaternion_tolerance must be in [0, 1)");
  if (!l.workspace_min.allFinite() || !l.workspace_max.allFinite() ||
      !(l.workspace_min.array() < l.workspace_max.array()).all())
    throw std::invalid_argument("~limits/workspace_min must be below workspace_max on every axis");
  if (l.max_objects == 0 || l.max_name_length == 0)
    throw std::invalid_argument("~limits/max_objects and max_name_length must be > 0");
}

double checkedDurationScale(double scale, const RequestLimits& l) {
  if (scale == 0.0) return 1.0;
  if (!std::isfinite(scale) || scale < l.min_duration_scale || scale > l.max_duration_scale)
    throw std::invalid_argument("duration_scale " + formatted(scale) + " is outside [" +
                                formatted(l.min_duration_scale) + ", " +
                                formatted(l.max_duration_scale) +
                                "] (~limits/min_duration_scale, ~limits/max_duration_scale)");
  return scale;
}

lfd::Pose checkedPose(const Eigen::Vector3d& position, const Eigen::Vector4d& wxyz,
                      const std::string& what, const RequestLimits& l) {
  if (!position.allFinite() || !wxyz.allFinite())
    throw std::invalid_argument(what + " has a NaN or infinite value");
  const double norm = wxyz.norm();
  if (norm < 1e-9)
    throw std::invalid_argument(what +
                                " has a zero quaternion (no orientation; identity is "
                                "w = 1)");
  if (std::abs(norm - 1.0) > l.quaternion_tolerance)
    throw std::invalid_argument(what + " has a quaternion of norm " + formatted(norm) +
                                ", not a rotation (|norm - 1| over ~limits/quaternion_tolerance " +
                                formatted(l.quaternion_tolerance) + ")");
  lfd::Pose p;
  p.position = position;
  p.orientation = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
  return p;
}

void checkInWorkspace(const lfd::Pose& pose, const std::string& what, const RequestLimits& l) {
  if (!pose.position.allFinite() || (pose.position.array() < l.workspace_min.array()).any() ||
      (pose.position.array() > l.workspace_max.array()).any()) {
    std::ostringstream m;
    m << what << " at (" << pose.position.transpose() << ") is outside the workspace ["
      << l.workspace_min.transpose() << "] .. [" << l.workspace_max.transpose()
      << "] m (~limits/workspace_min, ~limits/workspace_max)";
    throw std::invalid_argument(m.str());
  }
}

void checkObjectNames(const std::vector<std::string>& names, size_t poses, const RequestLimits& l) {
  if (names.size() != poses)
    throw std::invalid_argument(std::to_string(names.size()) + " object names but " +
                                std::to_string(poses) + " object poses");
  if (names.size() > l.max_objects)
    throw std::invalid_argument(std::to_string(names.size()) + " objects, over the limit of " +
                                std::to_string(l.max_objects) + " (~limits/max_objects)");
  std::set<std::string> seen;
  for (const std::string& n : names) {
    if (n.empty()) throw std::invalid_argument("an object name is empty");
    checkNameLength(n, "object name", l);
    if (!seen.insert(n).second)
      throw std::invalid_argument("object '" + n + "' is named twice in the scene");
  }
}

void checkNameLength(const std::string& text, const std::string& what, const RequestLimits& l) {
  if (text.size() > l.max_name_length)
    throw std::invalid_argument(what + " '" + clipped(text) + "' is over " +
                                std::to_string(l.max_name_length) +
                                " characters (~limits/max_name_length)");
}

}  // namespace lfd_dmp
