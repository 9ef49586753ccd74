// Errors of bag readers that name what a user can look up: rosbag reports a message whose bytes
// do not fit its connection's declared type (a lying connection header, a truncated message) as
// "Buffer Overrun", with no file, topic or message.
#pragma once

#include <cstddef>
#include <string>

namespace lfd {

/// "bag '<file>': message <index> on <topic> (declared <type>) at t = <time> s: its bytes do not
/// match the declared message definition (<detail>)". `index` counts the topic's messages in the
/// bag from 0; `time` is the bag's receive time (s); user text is quoted short.
std::string mismatchedMessageError(const std::string& file, const std::string& topic,
                                   const std::string& type, std::size_t index, double time,
                                   const std::string& detail);

}  // namespace lfd
