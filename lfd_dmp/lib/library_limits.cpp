#include "lfd_dmp/library_limits.hpp"

#include "lfd_dmp/skill_library.hpp"

#include <lfd_core/io/user_text.hpp>

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace lfd_dmp {
namespace {

using nlohmann::json;

[[noreturn]] void refuse(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

std::string over(std::size_t size, std::size_t limit, const char* key) {
  return std::to_string(size) + " is over the limit of " + std::to_string(limit) +
         " (library_limits/" + key + ")";
}

// A library is a few levels deep; a deeper document is no library (and no stack overflow here).
constexpr int kMaxDepth = 32;

// Every string, key and array of the document, wherever it is: a 10 MB demo_id or warning was
// written into a library and echoed into 839 MB of feedback. Numbers (the bulk) cost no path.
void checkTree(const json& j, const std::string& where, const LibraryLimits& limits, int depth) {
  if (depth > kMaxDepth) refuse(where, "nested deeper than " + std::to_string(kMaxDepth));
  if (j.is_string() && j.get_ref<const std::string&>().size() > limits.max_string_length)
    refuse(where, "a string of " + over(j.get_ref<const std::string&>().size(),
                                        limits.max_string_length, "max_string_length"));
  if (j.is_array() && j.size() > limits.max_list_length)
    refuse(where, "a list of " + over(j.size(), limits.max_list_length, "max_list_length"));
  if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i)
      if (!j[i].is_number())
        checkTree(j[i], where + "[" + std::to_string(i) + "]", limits, depth + 1);
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      const std::string at = where + "." + lfd::printable(key, 40);
      if (key.size() > limits.max_string_length)
        refuse(at, "a key of " + over(key.size(), limits.max_string_length, "max_string_length"));
      checkTree(value, at, limits, depth + 1);
    }
  }
}

std::size_t sizeAt(const json& j, const char* key) {
  const auto it = j.is_object() ? j.find(key) : j.end();
  return it != j.end() && it->is_array() ? it->size() : 0;
}

std::string seconds(double s) {
  std::ostringstream out;
  out << s << " s";
  return out.str();
}

}  // namespace

void checkLibraryLimits(const LibraryLimits& l) {
  auto need = [](bool ok, const char* key, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("library_limits/") + key + " " + what);
  };
  need(l.min_tau > 0.0 && std::isfinite(l.min_tau), "min_tau", "must be > 0 (s)");
  need(l.max_tau >= l.min_tau && std::isfinite(l.max_tau), "max_tau", "must be >= min_tau (s)");
  need(l.max_tau_ratio >= 1.0, "max_tau_ratio", "must be >= 1");
  need(l.max_segments > 0 && l.max_demos > 0 && l.max_num_basis >= 2 && l.max_list_length > 0 &&
           l.max_string_length > 0 && l.max_file_bytes > 0,
       "max_*", "must be > 0 (max_num_basis >= 2)");
}

void checkLibrarySizes(const json& library, const LibraryLimits& limits) {
  const std::size_t segments = sizeAt(library, "segments");
  if (segments > limits.max_segments)
    refuse("segments", over(segments, limits.max_segments, "max_segments") + " segments");
  if (sizeAt(library, "demo_scenes") > limits.max_demos)
    refuse("demo_scenes",
           over(sizeAt(library, "demo_scenes"), limits.max_demos, "max_demos") + " scenes");
  for (std::size_t s = 0; s < segments; ++s) {
    const std::size_t demos = sizeAt(library["segments"][s], "demos");
    if (demos > limits.max_demos)
      refuse("segments[" + std::to_string(s) + "].demos",
             over(demos, limits.max_demos, "max_demos") + " demos");
  }
  const json* basis = library.contains("dmp_parameters") && library["dmp_parameters"].is_object()
                          ? &library["dmp_parameters"]
                          : nullptr;
  if (basis && basis->contains("num_basis") && (*basis)["num_basis"].is_number() &&
      !((*basis)["num_basis"].get<double>() <= limits.max_num_basis))
    refuse("dmp_parameters.num_basis", "over the limit of " + std::to_string(limits.max_num_basis) +
                                           " (library_limits/max_num_basis)");
  checkTree(library, "skill library", limits, 0);
}

void checkLibraryDurations(const SkillLibrary& library, const LibraryLimits& limits) {
  for (std::size_t s = 0; s < library.segments.size(); ++s) {
    const SegmentSkills& seg = library.segments[s];
    for (std::size_t d = 0; d < seg.demos.size(); ++d) {
      const DemoSkill& demo = seg.demos[d];
      const std::string where = "segments[" + std::to_string(s) + "] " + lfd::quoted(seg.name) +
                                ", demos[" + std::to_string(d) + "] " + lfd::quoted(demo.demo_id);
      const double tau = demo.dmp.tau, own = demo.end_time - demo.start_time;
      const std::string bounds = " outside [" + seconds(limits.min_tau) + ", " +
                                 seconds(limits.max_tau) + "] (library_limits/min_tau, max_tau)";
      if (!(tau >= limits.min_tau && tau <= limits.max_tau))
        refuse(where + ".dmp.tau", seconds(tau) + bounds + ": no arm follows that");
      if (!(own >= limits.min_tau && own <= limits.max_tau))
        refuse(where + ".end_time - start_time", seconds(own) + bounds);
      const double ratio = tau > own ? tau / own : own / tau;
      if (!(ratio <= limits.max_tau_ratio))
        refuse(where + ".dmp.tau",
               seconds(tau) + " for a demonstrated segment of " + seconds(own) +
                   " (end_time - start_time): a factor over library_limits/max_tau_ratio (" +
                   std::to_string(limits.max_tau_ratio) + ")");
    }
  }
}

}  // namespace lfd_dmp
