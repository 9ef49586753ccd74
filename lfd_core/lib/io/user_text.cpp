#include "lfd_core/io/user_text.hpp"

#include <cstdio>
#include <stdexcept>

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

void stripByteOrderMark(std::string& first_line, const std::string& path) {
  static const std::string kUtf8 = "\xEF\xBB\xBF";
  if (first_line.compare(0, kUtf8.size(), kUtf8) == 0) {
    first_line.erase(0, kUtf8.size());
    return;
  }
  const bool le = first_line.compare(0, 2, "\xFF\xFE") == 0;
  if (le || first_line.compare(0, 2, "\xFE\xFF") == 0) {
    throw std::invalid_argument(
        "file " + quoted(path) + " is UTF-16 (it starts with the byte-order mark " +
        (le ? "FF FE" : "FE FF") + "): UTF-16 is not supported, save it as UTF-8");
  }
}

}  // namespace lfd
