// One budget for the files a request makes a node read, computed from the expanded work (every
// file after a demo's parts are split out, their total size) and checked before any work starts
// (32 request entries of 290 bag parts passed a limit of 32 bags, then took 120 s
// and 581 MB and blocked the next request), and one bound for every string a request carries
// (a 10 MB string was echoed into errors, logs and feedback). Every refusal names its config key.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "lfd_core/io/ros_message_schema.hpp"
#include "lfd_core/io/safe_paths.hpp"

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

/// The longest string a request field may hold. The default is the longest legitimate one: a
/// demo of max_bag_files (64) parts, each a path of PATH_MAX (4096) bytes, joined by commas.
constexpr std::size_t kDefaultMaxRequestStringBytes = 64 * 4096 + 63;

struct StringBudget {
  std::size_t max_bytes = kDefaultMaxRequestStringBytes;  ///< 0 = no bound
  std::string key = "limits/max_request_string_bytes";    ///< its config key, for messages
};

/// Refuses one request string over the budget: "<field>: a string of N bytes, over the limit of
/// M (<key>): '<its first 200 characters>...'".
void checkRequestString(const std::string& field, std::string_view value,
                        const StringBudget& budget);

/// checkRequestString for every string of a serialized request (any depth, every array element),
/// each named by its field path ("bag_paths[2]", "metadata.task"). Nodes call it through
/// lfd_ros/ros_request_strings.hpp before any other work.
void checkMessageStrings(const rosmsg::MessageSchema& schema, const std::uint8_t* data,
                         std::size_t size, const StringBudget& budget);

}  // namespace lfd
