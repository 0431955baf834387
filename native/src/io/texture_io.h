// Texture images for material programs (Scene::images) on disk, for RIB files:
// the writer stores each image as a 32-bit float RGBA OpenEXR file, so its
// texels read back bit for bit; the reader also takes PNGs (8 bits per channel).
#pragma once

#include <string>

#include "micropoly/scene.h"

namespace mp {

// Writes `image` as an RGBA float EXR, top row first (as image viewers expect;
// the Scene stores rows bottom to top). Throws mp::Error on failure.
void write_texture_image(const std::string& path, const Image& image);

// Reads an EXR (any of R, G, B, A present; missing color channels are 0,
// missing alpha 1) or a PNG (8-bit RGBA, values in [0, 1] as stored, so an
// sRGB PNG gives sRGB-encoded values; 16-bit files are reduced to 8 bits). Rows come back bottom to top.
// Refuses images over `max_pixels` texels. Throws mp::Error on failure.
Image read_texture_image(const std::string& path, size_t max_pixels);

}  // namespace mp
