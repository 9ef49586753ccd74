// One budget for the files a request makes a node read, computed from the expanded work (every
// file after a demo's parts are split out, their total size) and checked before any work starts
// (issue 23 row 2: 32 request entries of 290 bag parts passed a limit of 32 bags, then took 120 s
// and 581 MB and blocked the next request). Every refusal names its config key.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "lfd_core/safe_paths.hpp"

namespace lfd {

struct InputBudget {
  std::string what = "files";         ///< what the files are, for messages ("bag files")
  std::size_t max_files = 0;          ///< 0 = no bound
  std::string max_files_key;          ///< its config key, e.g. "limits/max_bag_files"
  std::uint64_t max_total_bytes = 0;  ///< summed over the files; 0 = no bound
  std::string max_total_bytes_key;    ///< e.g. "limits/max_total_bytes"
};

/// Refuses `files` over the budget: their number first (nothing is opened), then their total size
/// (each opened by openInputFile under `policy`: a FIFO or a path outside the roots is refused
/// too). Returns the total size in bytes. Throws std::invalid_argument.
std::uint64_t checkInputBudget(const std::vector<std::string>& files, const InputBudget& budget,
                               const PathPolicy& policy = {});

}  // namespace lfd
