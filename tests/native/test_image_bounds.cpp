// Texture readers bound what an image header may claim by the file's real
// size (io/image_bounds.cpp): crafted headers are refused before any pixel
// memory is allocated, and real, highly compressed images still read.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/image_io.h"
#include "io/texture_io.h"
#include "micropoly/error.h"

namespace {

const std::string kCrafted = std::string(MICROPOLY_TEST_SCENES) + "/untrusted/";
constexpr size_t kManyTexels = size_t(1) << 40;  // no texel budget in the way

std::string read_error(const std::string& path) {
  try {
    mp::read_texture_image(path, kManyTexels);
  } catch (const mp::Error& e) {
    return e.what();
  }
  return "";
}

std::string temp(const std::string& name) {
  return ::testing::TempDir() + "/image_bounds_" + std::to_string(::getpid()) + "_" + name;
}

TEST(ImageBounds, CraftedPngHeadersAreRefused) {
  EXPECT_EQ(read_error(kCrafted + "png_100000x100000.png"),
            "texture '" + kCrafted + "png_100000x100000.png': its header claims 100000x100000 pixels, more than 69 "
            "bytes of deflate data can hold (at most 1032 bytes of pixels per byte)");
  EXPECT_NE(read_error(kCrafted + "png_10000x10000.png").find("claims 10000x10000 pixels, more than 69 bytes"),
            std::string::npos);
}

TEST(ImageBounds, CraftedExrHeadersAreRefused) {
  EXPECT_NE(read_error(kCrafted + "exr_10000x10000_zip.exr")
                .find("its header claims 10000x10000 pixels, more than 5347 bytes of ZIP data can hold"),
            std::string::npos);
  EXPECT_NE(read_error(kCrafted + "exr_100000x100000_dwaa.exr")
                .find("claims 100000x100000 pixels, more than 363 bytes of DWAA data can hold"),
            std::string::npos);
  // A header cut short, and an attribute whose size runs past the end.
  std::ifstream in(kCrafted + "exr_100000x100000_dwaa.exr", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string cut = temp("cut.exr");
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, 12);  // inside the first name
  // (OpenEXRCore's header reader names what is wrong.)
  EXPECT_NE(read_error(cut).find("not a readable OpenEXR file: File is not an OpenEXR file or has a bad header value"),
            std::string::npos)
      << read_error(cut);
  std::string long_attr = bytes;
  // The little-endian size of "channels" follows the magic, the version and
  // its name and type; 0x7f...7f claims about 2 GiB.
  long_attr[8 + 9 + 7] = '\x7f';
  long_attr[8 + 9 + 7 + 3] = '\x7f';
  const std::string past = temp("past.exr");
  std::ofstream(past, std::ios::binary) << long_attr;
  EXPECT_NE(read_error(past).find("not a readable OpenEXR file: Missing required attribute in part header"),
            std::string::npos)
      << read_error(past);
}

TEST(ImageBounds, FlatImagesStillRead) {
  // Flat images compress best; each must stay within the bound.
  mp::Image flat;
  flat.width = flat.height = 1024;
  flat.pixels.assign(1024 * 1024, glm::vec4(0.0f));
  const std::string exr = temp("flat.exr");
  mp::write_texture_image(exr, flat);
  const mp::Image back = mp::read_texture_image(exr, kManyTexels);
  EXPECT_EQ(back.width, 1024);
  EXPECT_EQ(back.pixels.size(), flat.pixels.size());
  mp::RenderResult black;
  black.width = black.height = 2048;
  black.rgba.assign(size_t(2048) * 2048 * 4, 0.0f);
  const std::string png = temp("flat.png");
  mp::write_image(png, black);
  EXPECT_EQ(mp::read_texture_image(png, kManyTexels).pixels.size(), size_t(2048) * 2048);
  std::filesystem::remove(exr);
  std::filesystem::remove(png);
}

TEST(ImageBounds, OnlyRegularFiles) {
  // A FIFO would block the reader forever.
  const std::string fifo = temp("fifo.png");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(read_error(fifo), "texture '" + fifo + "': not a regular file");
  std::filesystem::remove(fifo);
  EXPECT_NE(read_error(temp("missing.exr")).find("No such file"), std::string::npos);
}

}  // namespace
