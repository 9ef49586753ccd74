// Bounds a skill library must meet when it is loaded. A library is data a file brings, and the
// executor runs what it says: a tau of 1e-6 s (or 0.05 s for a 9.8 s task) "succeeded" in 0.1 s
// without moving, and a 300 MB library took 3.3 GB to parse. The defaults are executor.yaml's
// `library_limits:`, where each has its reason; every refusal names the JSON location and the key.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

namespace lfd_dmp {

struct SkillLibrary;

struct LibraryLimits {
  double min_tau = 0.1;                  ///< s; the segmentation's shortest skill is 1 s
  double max_tau = 300.0;                ///< s; a segment lies in one demo (learner: 120 s at most)
  double max_tau_ratio = 5.0;            ///< tau vs its demo's own segment (end_time - start_time)
  std::size_t max_segments = 64;         ///< tasks have 2-5
  std::size_t max_demos = 256;           ///< per segment, and demo scenes (learner: 32 bags)
  int max_num_basis = 1000;              ///< learner.yaml limits/max_num_basis
  std::size_t max_list_length = 1000;    ///< any JSON array: the longest is num_basis weights
  std::size_t max_string_length = 4096;  ///< any JSON string or key: demo ids are bag paths
  std::uintmax_t max_file_bytes = 64u << 20;  ///< learned libraries are 0.1-1 MB
};

/// Throws std::invalid_argument naming the key (library_limits/...) for a bad limit set.
void checkLibraryLimits(const LibraryLimits& limits);

/// Before anything is converted: every string and key, every array and the number of segments,
/// demos and basis functions. Throws std::runtime_error "<JSON location>: ...".
void checkLibrarySizes(const nlohmann::json& library, const LibraryLimits& limits);

/// After conversion: each demo's tau and its own segment duration within the physical bounds, and
/// tau within max_tau_ratio of that duration. Throws std::runtime_error naming the segment.
void checkLibraryDurations(const SkillLibrary& library, const LibraryLimits& limits);

}  // namespace lfd_dmp
