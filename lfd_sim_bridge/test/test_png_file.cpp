// Unit tests of the PNG writer (png_file.hpp): what it writes, libpng reads back as the same
// 8-bit RGB pixels, whatever the size; bad sizes and unwritable paths are clear errors.
#include <gtest/gtest.h>
#include <png.h>

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "lfd_sim_bridge/png_file.hpp"

namespace {

struct Decoded {
  int width = 0, height = 0;
  png_uint_32 format = 0;  // as stored in the file, before any conversion
  std::vector<std::uint8_t> rgb;
};

// Decoded by libpng itself (its simplified reader), independently of how the file was written.
Decoded readPng(const std::string& path) {
  png_image image;
  std::memset(&image, 0, sizeof(image));
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str()))
    throw std::runtime_error(path + ": " + image.message);
  Decoded d;
  d.width = static_cast<int>(image.width);
  d.height = static_cast<int>(image.height);
  d.format = image.format;
  image.format = PNG_FORMAT_RGB;
  d.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, d.rgb.data(), 0, nullptr))
    throw std::runtime_error(path + ": " + image.message);
  return d;
}

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("lfd_png_" + std::to_string(getpid()) + "_" + name))
      .string();
}

std::vector<std::uint8_t> noise(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(width) * height * 3);
  for (std::uint8_t& v : rgb) v = static_cast<std::uint8_t>(byte(rng));
  return rgb;
}

TEST(PngFile, LibpngReadsBackTheSamePixels) {
  // Noise (incompressible), a gradient and flat colour (compressible), odd and 1-pixel sizes.
  struct Case {
    int width, height;
    std::vector<std::uint8_t> rgb;
  };
  std::vector<Case> cases = {{640, 480, noise(640, 480, 1)},
                             {17, 33, noise(17, 33, 2)},
                             {1, 1, {255, 0, 128}},
                             {3, 1, noise(3, 1, 3)},
                             {1, 5, noise(1, 5, 4)}};
  std::vector<std::uint8_t> gradient(320 * 240 * 3);
  for (std::size_t i = 0; i < gradient.size(); ++i)
    gradient[i] = static_cast<std::uint8_t>((i / 3) % 320 * 255 / 319);
  cases.push_back({320, 240, gradient});
  cases.push_back({100, 50, std::vector<std::uint8_t>(100 * 50 * 3, 0)});
  cases.push_back({100, 50, std::vector<std::uint8_t>(100 * 50 * 3, 255)});
  for (const Case& c : cases) {
    const std::string path = tempPath(std::to_string(c.width) + "x" + std::to_string(c.height));
    lfd_sim_bridge::writePng(path, c.rgb, c.width, c.height);
    const Decoded d = readPng(path);
    EXPECT_EQ(d.width, c.width);
    EXPECT_EQ(d.height, c.height);
    EXPECT_EQ(d.format, static_cast<png_uint_32>(PNG_FORMAT_RGB)) << "8-bit RGB, no alpha";
    EXPECT_TRUE(d.rgb == c.rgb) << c.width << " x " << c.height;
    std::remove(path.c_str());
  }
}

TEST(PngFile, CompressesWhatRepeats) {
  const std::string path = tempPath("flat");
  lfd_sim_bridge::writePng(path, std::vector<std::uint8_t>(960 * 720 * 3, 90), 960, 720);
  EXPECT_LT(std::filesystem::file_size(path), 20000u);  // 2 MB of one colour
  std::ifstream f(path, std::ios::binary);
  char signature[8] = {};
  f.read(signature, 8);
  EXPECT_EQ(std::string(signature, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::remove(path.c_str());
}

TEST(PngFile, BadSizesAndPathsAreErrors) {
  EXPECT_THROW(lfd_sim_bridge::writePng(tempPath("short"), std::vector<std::uint8_t>(11), 2, 2),
               std::invalid_argument);
  EXPECT_THROW(lfd_sim_bridge::writePng(tempPath("zero"), {}, 0, 0), std::invalid_argument);
  const std::string missing = "/nonexistent_lfd_dir/picture.png";
  try {
    lfd_sim_bridge::writePng(missing, std::vector<std::uint8_t>(12, 1), 2, 2);
    FAIL() << "wrote into a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

}  // namespace
