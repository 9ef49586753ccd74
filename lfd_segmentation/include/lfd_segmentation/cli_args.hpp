// Command-line pieces the master-free CLIs share (segment, signature).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace lfd_segmentation {

/// "a,b,,c" -> {a, b, c}.
inline std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

inline bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// The value after option argv[*k] (advancing *k); throws "<option> needs a value".
inline std::string optionValue(int argc, char** argv, int* k) {
  const std::string option = argv[*k];
  if (*k + 1 >= argc) throw std::invalid_argument(option + " needs a value");
  return argv[++*k];
}

}  // namespace lfd_segmentation
