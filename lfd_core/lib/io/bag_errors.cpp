#include "lfd_core/io/bag_errors.hpp"

#include <sstream>

#include "lfd_core/io/user_text.hpp"

namespace lfd {

std::string mismatchedMessageError(const std::string& file, const std::string& topic,
                                   const std::string& type, std::size_t index, double time,
                                   const std::string& detail) {
  std::ostringstream out;
  out.precision(3);
  out << std::fixed << "bag " << quoted(file) << ": message " << index << " on " << quoted(topic)
      << " (declared " << quoted(type) << ") at t = " << time
      << " s: its bytes do not match the declared message definition (" << printable(detail) << ")";
  return out.str();
}

}  // namespace lfd
