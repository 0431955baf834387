// Writes render results to image files: PNG (8-bit sRGB, straight alpha) via
// libpng and EXR (32-bit float RGBA premultiplied, plus Z and N.xyz) via OpenEXR.
#pragma once

#include <string>

#include "micropoly/render_result.h"

namespace mp {

// Format from the extension (.png or .exr); throws mp::Error on failure.
void write_image(const std::string& path, const RenderResult& result);

// Scene-linear to sRGB-encoded (IEC 61966-2-1) value in [0, 1].
float linear_to_srgb(float v);

}  // namespace mp
