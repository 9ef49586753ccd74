#include "lfd_core/io/input_budget.hpp"

#include <stdexcept>

#include "lfd_core/io/ros_message_reader.hpp"
#include "lfd_core/io/user_text.hpp"

namespace lfd {

std::uint64_t checkInputBudget(const std::vector<std::string>& files, const InputBudget& budget,
                               const PathPolicy& policy) {
  if (budget.max_files > 0 && files.size() > budget.max_files) {
    throw std::invalid_argument(std::to_string(files.size()) + " " + budget.what +
                                ", over the limit of " + std::to_string(budget.max_files) + " (" +
                                budget.max_files_key + ")");
  }
  std::uint64_t total = 0;
  for (const std::string& file : files) {
    total += openInputFile(file, policy).size();
    if (budget.max_total_bytes > 0 && total > budget.max_total_bytes) {
      throw std::invalid_argument(
          budget.what + " of over " + std::to_string(total) + " bytes, over the limit of " +
          std::to_string(budget.max_total_bytes) + " bytes (" + budget.max_total_bytes_key + ")");
    }
  }
  return total;
}

void checkRequestString(const std::string& field, std::string_view value,
                        const StringBudget& budget) {
  if (budget.max_bytes == 0 || value.size() <= budget.max_bytes) return;
  // Only the quoted head is copied: the whole value may be hundreds of megabytes.
  const std::string head(value.substr(0, kMaxQuotedChars));
  throw std::invalid_argument(field + ": a string of " + std::to_string(value.size()) +
                              " bytes, over the limit of " + std::to_string(budget.max_bytes) +
                              " (" + budget.key + "): " + quoted(head) + "...");
}

void checkMessageStrings(const rosmsg::MessageSchema& schema, const std::uint8_t* data,
                         std::size_t size, const StringBudget& budget) {
  rosmsg::forEachString(schema, data, size, [&](const std::string& path, std::string_view value) {
    checkRequestString(path, value, budget);
  });
}

}  // namespace lfd
