#include "lfd_core/user_text.hpp"

#include <cstdio>

namespace lfd {

std::string printable(const std::string& text, std::size_t max_chars) {
  std::string out;
  const std::size_t n = text.size() < max_chars ? text.size() : max_chars;
  out.reserve(n + 32);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[5];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    }
  }
  if (n < text.size()) out += "... (" + std::to_string(text.size()) + " bytes)";
  return out;
}

std::string quoted(const std::string& text, std::size_t max_chars) {
  return "'" + printable(text, max_chars) + "'";
}

}  // namespace lfd
