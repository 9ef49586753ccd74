// User input quoted in errors and logs: a request or a file may hold any bytes (a 10 MB string,
// invalid UTF-8, control characters), and an error message must stay short, printable and valid
// wherever it goes (a terminal, a log line, a JSON answer, a ROS string field).
#pragma once

#include <cstddef>
#include <string>

namespace lfd {

/// How many characters of one user-supplied value an error message quotes (issue 23: a 10 MB
/// string was echoed whole into errors and logs). Enough for any real path or name.
constexpr std::size_t kMaxQuotedChars = 200;

/// `text` fit for an error message: bytes outside printable ASCII as \xNN (so the message is
/// valid UTF-8 whatever the input), cut after `max_chars` input bytes with a note of the total.
std::string printable(const std::string& text, std::size_t max_chars = kMaxQuotedChars);

/// printable() in single quotes: "'" + printable(text) + "'".
std::string quoted(const std::string& text, std::size_t max_chars = kMaxQuotedChars);

}  // namespace lfd
