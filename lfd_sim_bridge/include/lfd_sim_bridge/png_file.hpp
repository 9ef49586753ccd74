// PNG files of rendered pictures (ROS-free), encoded by libpng: what the snapshot tool writes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace lfd_sim_bridge {

// Writes `rgb` (width * height * 3 bytes, 8-bit RGB, the top row first) as a PNG file. Throws
// std::invalid_argument when the sizes disagree, std::runtime_error naming the file when libpng
// cannot write it.
void writePng(const std::string& path, const std::vector<std::uint8_t>& rgb, int width, int height);

}  // namespace lfd_sim_bridge
