// Bounds on what an image file can really hold, checked against the size its
// header claims before anything is allocated for the pixels: a header is a
// few bytes an attacker writes freely, the file's length is not.
#pragma once

#include <cstdint>
#include <string>

namespace mp {

// The size of the regular file at `path` in bytes. Throws mp::Error naming
// the file when it is missing or not a regular file (a FIFO or a device
// would never end).
uint64_t image_file_bytes(const std::string& path);

// Throws mp::Error unless a PNG of `file_bytes` bytes can hold `width` x
// `height` pixels (see image_bounds.cpp for the bound).
void check_png_claim(const std::string& path, uint64_t file_bytes, uint64_t width, uint64_t height);

// Reads the first part's header of the OpenEXR file at `path` (data window,
// compression, channels; OpenEXRCore) with no allocation driven by it, and throws
// mp::Error unless a file of its size can hold that many pixels.
void check_exr_claim(const std::string& path, uint64_t file_bytes);

}  // namespace mp
