#include "lfd_sim_bridge/png_file.hpp"

#include <png.h>

#include <cstring>
#include <stdexcept>

namespace lfd_sim_bridge {

void writePng(const std::string& path, const std::vector<std::uint8_t>& rgb, int width,
              int height) {
  if (width <= 0 || height <= 0 ||
      rgb.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    throw std::invalid_argument("writePng: " + std::to_string(rgb.size()) + " bytes for a " +
                                std::to_string(width) + " x " + std::to_string(height) +
                                " RGB picture");
  // libpng's simplified API: no setjmp error handling to get right, errors come back in
  // image.message.
  png_image image;
  std::memset(&image, 0, sizeof(image));
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&image, path.c_str(), /*convert_to_8bit=*/0, rgb.data(),
                               /*row_stride=*/0, /*colormap=*/nullptr))
    throw std::runtime_error("cannot write '" + path + "': " + image.message);
}

}  // namespace lfd_sim_bridge
