#include "io/image_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "micropoly/error.h"

namespace mp {
namespace {

std::string lower_extension(const std::string& path) {
  auto dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void write_png(const std::string& path, const RenderResult& r) {
  std::vector<unsigned char> pixels(static_cast<size_t>(r.width) * r.height * 4);
  for (size_t i = 0; i < static_cast<size_t>(r.width) * r.height; ++i) {
    float a = std::clamp(r.rgba[4 * i + 3], 0.0f, 1.0f);
    for (int c = 0; c < 3; ++c) {
      float v = a > 0 ? r.rgba[4 * i + c] / a : 0.0f;  // PNG stores straight alpha
      pixels[4 * i + c] = static_cast<unsigned char>(std::lround(linear_to_srgb(v) * 255.0f));
    }
    pixels[4 * i + 3] = static_cast<unsigned char>(std::lround(a * 255.0f));
  }
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) throw Error("cannot open '" + path + "' for writing");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw Error("libpng could not start writing '" + path + "'");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error("libpng failed while writing '" + path + "'");
  }
  png_init_io(png, file.get());
  png_set_IHDR(png, info, static_cast<png_uint_32>(r.width), static_cast<png_uint_32>(r.height), 8, PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  for (int y = 0; y < r.height; ++y) png_write_row(png, &pixels[static_cast<size_t>(y) * r.width * 4]);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
}

void write_exr(const std::string& path, const RenderResult& r) {
  try {
    Imf::Header header(r.width, r.height);
    // Colour always; Depth (Z) and Normal (N.*) each where the result has it.
    const char* names[] = {"R", "G", "B", "A", "Z", "N.X", "N.Y", "N.Z"};
    const bool depth = !r.depth.empty(), normal = !r.normal.empty();
    for (int c = 0; c < 8; ++c)
      if (c < 4 || (c == 4 && depth) || (c > 4 && normal)) header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    const size_t xs4 = 4 * sizeof(float), ys4 = xs4 * r.width;
    char* rgba = reinterpret_cast<char*>(const_cast<float*>(r.rgba.data()));
    for (int c = 0; c < 4; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, rgba + c * sizeof(float), xs4, ys4));
    if (depth)
      fb.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(r.depth.data())), sizeof(float),
                                sizeof(float) * r.width));
    if (normal) {
      char* n = reinterpret_cast<char*>(const_cast<float*>(r.normal.data()));
      for (int c = 0; c < 3; ++c)
        fb.insert(names[5 + c],
                  Imf::Slice(Imf::FLOAT, n + c * sizeof(float), 3 * sizeof(float), 3 * sizeof(float) * r.width));
    }
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(r.height);
  } catch (const std::exception& e) {
    throw Error("cannot write '" + path + "': " + e.what());
  }
}

}  // namespace

float linear_to_srgb(float v) {
  if (!(v > 0.0f)) return 0.0f;
  if (v >= 1.0f) return 1.0f;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

void write_image(const std::string& path, const RenderResult& result) {
  std::string ext = lower_extension(path);
  if (ext == "png")
    write_png(path, result);
  else if (ext == "exr")
    write_exr(path, result);
  else
    throw Error("unknown image format for '" + path + "': use .png or .exr");
}

}  // namespace mp
