#include "io/image_bounds.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <memory>

#include <OpenEXR/openexr.h>

#include "micropoly/error.h"

namespace mp {
namespace {

// The most bytes deflate (RFC 1951) can expand one compressed byte into:
// a 258-byte match costs at least 2 bits, plus block overhead, so the limit
// is 1032:1 (zlib's technical notes, "Maximum compression factor").
constexpr double kDeflateRatio = 1032.0;

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw Error("texture '" + path + "': " + why);
}

[[noreturn]] void too_large(const std::string& path, uint64_t width, uint64_t height, uint64_t file_bytes,
                            const char* codec, double ratio) {
  refuse(path, "its header claims " + std::to_string(width) + "x" + std::to_string(height) + " pixels, more than " +
                   std::to_string(file_bytes) + " bytes of " + codec + " data can hold (at most " +
                   std::to_string(static_cast<uint64_t>(ratio)) + " bytes of pixels per byte)");
}

// OpenEXRCore reports errors through a callback that prints by default; the
// result codes carry what is needed here.
void quiet(exr_const_context_t, exr_result_t, const char*) {}

// Bytes of pixel data per compressed byte at most, by OpenEXR compression
// (the "compression" attribute's values in the file layout).
double exr_ratio(exr_compression_t compression, const char** name) {
  switch (compression) {
    case EXR_COMPRESSION_NONE: *name = "uncompressed"; return 1.0;
    // A run record (count, value) stands for at most 128 bytes.
    case EXR_COMPRESSION_RLE: *name = "RLE"; return 64.0;
    // zlib over the bytes (ZIPS: one line per block, ZIP: 16).
    case EXR_COMPRESSION_ZIPS: *name = "ZIPS"; return kDeflateRatio;
    case EXR_COMPRESSION_ZIP: *name = "ZIP"; return kDeflateRatio;
    // zlib over 24-bit floats that expand to 32 bits.
    case EXR_COMPRESSION_PXR24: *name = "PXR24"; return kDeflateRatio * 4.0 / 3.0;
    // A flat 4x4 block of halves (32 bytes) packs into 3 bytes.
    case EXR_COMPRESSION_B44: *name = "B44"; return 32.0 / 3.0 + 1.0;
    case EXR_COMPRESSION_B44A: *name = "B44A"; return 32.0 / 3.0 + 1.0;
    // PIZ (wavelet, then Huffman with run codes) and DWAA/DWAB (DCT, then
    // run-length and zlib coding) stack several coders, so no tight figure
    // is derived; 2^17 bytes per byte is far above what they reach on a
    // flat image and still refuses absurd headers.
    case EXR_COMPRESSION_PIZ: *name = "PIZ"; return 131072.0;
    case EXR_COMPRESSION_DWAA: *name = "DWAA"; return 131072.0;
    case EXR_COMPRESSION_DWAB: *name = "DWAB"; return 131072.0;
    default: *name = "unknown"; return 131072.0;
  }
}

}  // namespace

uint64_t image_file_bytes(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) refuse(path, std::strerror(errno));
  if (!S_ISREG(st.st_mode)) refuse(path, "not a regular file");
  return static_cast<uint64_t>(st.st_size);
}

// PNG (ISO/IEC 15948): the image data is one zlib stream that inflates to,
// per row, a filter byte plus at least one bit per pixel, so a W x H image
// needs H * (1 + ceil(W / 8)) bytes after inflation, and the file (which
// holds that stream) at least 1/1032 of it.
void check_png_claim(const std::string& path, uint64_t file_bytes, uint64_t width, uint64_t height) {
  const double raw = double(height) * (1.0 + double((width + 7) / 8));
  if (raw > kDeflateRatio * double(file_bytes)) too_large(path, width, height, file_bytes, "deflate", kDeflateRatio);
}

// The header is read by OpenEXRCore, which parses attributes within the
// file's bytes and allocates nothing from the data window until chunks are
// read (this never reads them): the data window, compression and channels
// of the first part.
void check_exr_claim(const std::string& path, uint64_t file_bytes) {
  exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
  init.error_handler_fn = quiet;
  exr_context_t raw = nullptr;
  const exr_result_t opened = exr_start_read(&raw, path.c_str(), &init);
  std::unique_ptr<exr_context_t, void (*)(exr_context_t*)> context(&raw, [](exr_context_t* c) {
    if (*c) exr_finish(c);
  });
  if (opened != EXR_ERR_SUCCESS) refuse(path, std::string("not a readable OpenEXR file: ") + exr_get_default_error_message(opened));
  exr_attr_box2i_t box{};
  exr_compression_t compression = EXR_COMPRESSION_NONE;
  const exr_attr_chlist_t* channels = nullptr;
  if (exr_get_data_window(raw, 0, &box) != EXR_ERR_SUCCESS || exr_get_compression(raw, 0, &compression) != EXR_ERR_SUCCESS ||
      exr_get_channels(raw, 0, &channels) != EXR_ERR_SUCCESS || !channels)
    refuse(path, "malformed OpenEXR header");
  double bytes_per_pixel = 0.0;
  for (int i = 0; i < channels->num_channels; ++i) {
    const exr_attr_chlist_entry_t& c = channels->entries[i];
    if (c.x_sampling < 1 || c.y_sampling < 1) refuse(path, "malformed OpenEXR channel list");
    bytes_per_pixel += (c.pixel_type == EXR_PIXEL_HALF ? 2.0 : 4.0) / (double(c.x_sampling) * double(c.y_sampling));
  }
  if (!(bytes_per_pixel > 0.0)) refuse(path, "OpenEXR file without channels");
  const int64_t w = int64_t(box.max.x) - box.min.x + 1, h = int64_t(box.max.y) - box.min.y + 1;
  if (w <= 0 || h <= 0) refuse(path, "empty OpenEXR data window");
  const char* codec = nullptr;
  const double ratio = exr_ratio(compression, &codec);
  if (double(w) * double(h) * bytes_per_pixel > ratio * double(file_bytes))
    too_large(path, uint64_t(w), uint64_t(h), file_bytes, codec, ratio);
}

}  // namespace mp
