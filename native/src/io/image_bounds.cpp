#include "io/image_bounds.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "micropoly/error.h"

namespace mp {
namespace {

// The most bytes deflate (RFC 1951) can expand one compressed byte into:
// a 258-byte match costs at least 2 bits, plus block overhead, so the limit
// is 1032:1 (zlib's technical notes, "Maximum compression factor").
constexpr double kDeflateRatio = 1032.0;

using File = std::unique_ptr<FILE, int (*)(FILE*)>;

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw Error("texture '" + path + "': " + why);
}

[[noreturn]] void too_large(const std::string& path, uint64_t width, uint64_t height, uint64_t file_bytes,
                            const char* codec, double ratio) {
  refuse(path, "its header claims " + std::to_string(width) + "x" + std::to_string(height) + " pixels, more than " +
                   std::to_string(file_bytes) + " bytes of " + codec + " data can hold (at most " +
                   std::to_string(static_cast<uint64_t>(ratio)) + " bytes of pixels per byte)");
}

bool read_exact(FILE* f, void* out, size_t n) { return std::fread(out, 1, n, f) == n; }

int32_t le32(const unsigned char* b) {
  return static_cast<int32_t>(uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24);
}

// A null-terminated name of at most `max_len` characters (OpenEXR file
// layout: 31, or 255 with the long-names flag).
bool read_name(FILE* f, size_t max_len, std::string* out) {
  out->clear();
  for (;;) {
    const int c = std::fgetc(f);
    if (c == EOF) return false;
    if (c == 0) return true;
    if (out->size() >= max_len) return false;
    out->push_back(static_cast<char>(c));
  }
}

// Bytes of pixel data per compressed byte at most, by OpenEXR compression
// (the "compression" attribute's values in the file layout).
double exr_ratio(int compression, const char** name) {
  switch (compression) {
    case 0: *name = "uncompressed"; return 1.0;
    // A run record (count, value) stands for at most 128 bytes.
    case 1: *name = "RLE"; return 64.0;
    // zlib over the bytes (ZIPS: one line per block, ZIP: 16).
    case 2: *name = "ZIPS"; return kDeflateRatio;
    case 3: *name = "ZIP"; return kDeflateRatio;
    // zlib over 24-bit floats that expand to 32 bits.
    case 5: *name = "PXR24"; return kDeflateRatio * 4.0 / 3.0;
    // A flat 4x4 block of halves (32 bytes) packs into 3 bytes.
    case 6: *name = "B44"; return 32.0 / 3.0 + 1.0;
    case 7: *name = "B44A"; return 32.0 / 3.0 + 1.0;
    // PIZ (wavelet, then Huffman with run codes) and DWAA/DWAB (DCT, then
    // run-length and zlib coding) stack several coders, so no tight figure
    // is derived; 2^17 bytes per byte is far above what they reach on a
    // flat image and still refuses absurd headers.
    case 4: *name = "PIZ"; return 131072.0;
    case 8: *name = "DWAA"; return 131072.0;
    case 9: *name = "DWAB"; return 131072.0;
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

// OpenEXR file layout: magic 20000630, a version word with flags, then the
// header's attributes (name, type name, int32 size, value) up to an empty
// name. Only dataWindow (box2i), compression (uchar) and channels (chlist)
// are read; other values, previews included, are skipped by their size,
// which must lie inside the file.
void check_exr_claim(const std::string& path, uint64_t file_bytes) {
  File f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) refuse(path, std::strerror(errno));
  unsigned char head[8];
  if (!read_exact(f.get(), head, 8) || le32(head) != 20000630) refuse(path, "not an OpenEXR file");
  const uint32_t flags = static_cast<uint32_t>(le32(head + 4));
  const size_t max_name = (flags & 0x400u) ? 255 : 31;  // long names
  bool have_window = false;
  int32_t box[4] = {0, 0, -1, -1};
  int compression = 0;
  double bytes_per_pixel = 0.0;
  bool have_channels = false;
  std::string name, type;
  for (;;) {
    if (!read_name(f.get(), max_name, &name)) refuse(path, "malformed OpenEXR header");
    if (name.empty()) break;
    unsigned char sb[4];
    if (!read_name(f.get(), max_name, &type) || !read_exact(f.get(), sb, 4)) refuse(path, "malformed OpenEXR header");
    const int32_t size = le32(sb);
    const long at = std::ftell(f.get());
    if (size < 0 || at < 0 || uint64_t(at) + uint64_t(size) > file_bytes)
      refuse(path, "OpenEXR attribute '" + name + "' runs past the end of the file");
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      unsigned char b[16];
      if (!read_exact(f.get(), b, 16)) refuse(path, "malformed OpenEXR header");
      for (int i = 0; i < 4; ++i) box[i] = le32(b + 4 * i);
      have_window = true;
    } else if (name == "compression" && type == "compression" && size == 1) {
      compression = std::fgetc(f.get());
    } else if (name == "channels" && type == "chlist") {
      if (size > (1 << 16)) refuse(path, "OpenEXR channel list over 64 KiB");
      // Each channel: name, pixel type (0 uint, 1 half, 2 float), pLinear,
      // 3 reserved bytes, x and y sampling; an empty name ends the list.
      std::vector<unsigned char> v(static_cast<size_t>(size));
      if (!read_exact(f.get(), v.data(), v.size())) refuse(path, "malformed OpenEXR header");
      size_t i = 0;
      while (i < v.size() && v[i] != 0) {
        while (i < v.size() && v[i] != 0) ++i;
        if (i + 17 > v.size()) refuse(path, "malformed OpenEXR channel list");
        const int32_t pixel_type = le32(&v[i + 1]), xs = le32(&v[i + 9]), ys = le32(&v[i + 13]);
        if (pixel_type < 0 || pixel_type > 2 || xs < 1 || ys < 1) refuse(path, "malformed OpenEXR channel list");
        bytes_per_pixel += (pixel_type == 1 ? 2.0 : 4.0) / (double(xs) * double(ys));
        i += 17;
      }
      have_channels = true;
    } else if (std::fseek(f.get(), size, SEEK_CUR) != 0) {
      refuse(path, "malformed OpenEXR header");
    }
  }
  if (!have_window) refuse(path, "OpenEXR header without a data window");
  if (!have_channels || !(bytes_per_pixel > 0.0)) refuse(path, "OpenEXR file without channels");
  const int64_t w = int64_t(box[2]) - box[0] + 1, h = int64_t(box[3]) - box[1] + 1;
  if (w <= 0 || h <= 0) refuse(path, "empty OpenEXR data window");
  const char* codec = nullptr;
  const double ratio = exr_ratio(compression, &codec);
  if (double(w) * double(h) * bytes_per_pixel > ratio * double(file_bytes))
    too_large(path, uint64_t(w), uint64_t(h), file_bytes, codec, ratio);
}

}  // namespace mp
