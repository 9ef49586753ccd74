#include "lfd_core/input_budget.hpp"

#include <stdexcept>

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

}  // namespace lfd
