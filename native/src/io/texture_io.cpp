#include "io/texture_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <memory>
#include <vector>

#include "io/image_bounds.h"
#include "micropoly/error.h"

namespace mp {
namespace {

bool has_extension(const std::string& path, const char* ext) {
  const size_t n = std::strlen(ext);
  if (path.size() < n) return false;
  for (size_t i = 0; i < n; ++i)
    if (std::tolower(static_cast<unsigned char>(path[path.size() - n + i])) != ext[i]) return false;
  return true;
}

void check_size(const std::string& path, long long width, long long height, size_t max_pixels) {
  if (width <= 0 || height <= 0 || static_cast<unsigned long long>(width) * static_cast<unsigned long long>(height) > max_pixels)
    throw Error("texture '" + path + "' is " + std::to_string(width) + "x" + std::to_string(height) +
                " texels; at most " + std::to_string(max_pixels) + " are accepted");
}

// Reverses the row order (files store the top row first, the Scene the bottom).
void flip_rows(Image& im) {
  const size_t w = static_cast<size_t>(im.width);
  for (int y = 0; y < im.height / 2; ++y)
    std::swap_ranges(im.pixels.begin() + static_cast<long>(y * w), im.pixels.begin() + static_cast<long>((y + 1) * w),
                     im.pixels.begin() + static_cast<long>((im.height - 1 - y) * w));
}

Image read_exr(const std::string& path, size_t max_pixels) {
  // The header's claim is checked against the file's size before OpenEXR
  // sizes its tables from it.
  check_exr_claim(path, image_file_bytes(path));
  Image im;
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i win = file.header().dataWindow();
    const long long w = static_cast<long long>(win.max.x) - win.min.x + 1;
    const long long h = static_cast<long long>(win.max.y) - win.min.y + 1;
    check_size(path, w, h, max_pixels);
    im.width = static_cast<int>(w);
    im.height = static_cast<int>(h);
    im.pixels.assign(static_cast<size_t>(w * h), glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    // Slices are addressed from the data window's origin.
    char* base = reinterpret_cast<char*>(im.pixels.data()) -
                 (static_cast<long long>(win.min.x) + static_cast<long long>(win.min.y) * w) * sizeof(glm::vec4);
    Imf::FrameBuffer fb;
    const char* names[] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), sizeof(glm::vec4),
                                     sizeof(glm::vec4) * static_cast<size_t>(w), 1, 1, c == 3 ? 1.0 : 0.0));
    file.setFrameBuffer(fb);
    file.readPixels(win.min.y, win.max.y);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error("cannot read texture '" + path + "': " + e.what());
  }
  flip_rows(im);
  return im;
}

Image read_png(const std::string& path, size_t max_pixels) {
  const uint64_t file_bytes = image_file_bytes(path);
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw Error("cannot read texture '" + path + "': " + png.message);
  Image im;
  std::vector<png_byte> data;
  try {
    check_png_claim(path, file_bytes, png.width, png.height);
    check_size(path, png.width, png.height, max_pixels);
    im.width = static_cast<int>(png.width);
    im.height = static_cast<int>(png.height);
    data.resize(static_cast<size_t>(png.width) * png.height * 4);
  } catch (...) {
    png_image_free(&png);  // png_image_finish_read frees it on every other path
    throw;
  }
  const size_t n = static_cast<size_t>(im.width) * static_cast<size_t>(im.height);
  // 8-bit RGBA as stored (16-bit files are reduced to 8-bit sRGB by libpng).
  png.format = PNG_FORMAT_RGBA;
  if (!png_image_finish_read(&png, nullptr, data.data(), 0, nullptr))
    throw Error("cannot read texture '" + path + "': " + png.message);
  im.pixels.resize(n);
  for (size_t i = 0; i < n; ++i)
    im.pixels[i] = glm::vec4(data[4 * i], data[4 * i + 1], data[4 * i + 2], data[4 * i + 3]) / 255.0f;
  flip_rows(im);
  return im;
}

}  // namespace

void write_texture_image(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * static_cast<size_t>(image.height))
    throw Error("texture '" + image.name + "' needs width * height pixels");
  try {
    Imf::Header header(image.width, image.height);
    const char* names[] = {"R", "G", "B", "A"};
    for (const char* c : names) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    Image top_first = image;  // EXR files store the top row first
    flip_rows(top_first);
    char* base = reinterpret_cast<char*>(top_first.pixels.data());
    Imf::FrameBuffer fb;
    for (int c = 0; c < 4; ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), sizeof(glm::vec4),
                                     sizeof(glm::vec4) * static_cast<size_t>(image.width)));
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    throw Error("cannot write texture '" + path + "': " + e.what());
  }
}

Image read_texture_image(const std::string& path, size_t max_pixels) {
  if (has_extension(path, ".exr")) return read_exr(path, max_pixels);
  if (has_extension(path, ".png")) return read_png(path, max_pixels);
  throw Error("texture '" + path + "': only .exr and .png textures are read");
}

}  // namespace mp
