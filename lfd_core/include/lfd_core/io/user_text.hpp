// User input quoted in errors and logs: a request or a file may hold any bytes (a 10 MB string,
// invalid UTF-8, control characters), and an error message must stay short, printable and valid
// wherever it goes (a terminal, a log line, a JSON answer, a ROS string field).
#pragma once

#include <cstddef>
#include <string>

namespace lfd {

/// How many characters of one user-supplied value an error message quotes (a 10 MB
/// string was echoed whole into errors and logs). Enough for any real path or name.
constexpr std::size_t kMaxQuotedChars = 200;

/// `text` fit for an error message: bytes outside printable ASCII as \xNN (so the message is
/// valid UTF-8 whatever the input), cut after `max_chars` input bytes with a note of the total.
std::string printable(const std::string& text, std::size_t max_chars = kMaxQuotedChars);

/// printable() in single quotes: "'" + printable(text) + "'".
std::string quoted(const std::string& text, std::size_t max_chars = kMaxQuotedChars);

/// The first line of a text file (CSV) as its reader wants it: a UTF-8 byte-order mark
/// (EF BB BF, which spreadsheet programs write) is removed, so the first column keeps its name
/// (it read as "no time column"). UTF-16 (a first FF FE or FE FF) is refused: std::invalid_argument
/// naming `path` and saying to save it as UTF-8.
void stripByteOrderMark(std::string& first_line, const std::string& path);

}  // namespace lfd
