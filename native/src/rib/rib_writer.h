// Writer for RIB: any valid Scene as a RIB file that read_rib_file() turns
// back into the same Scene, so that micropoly-render of an exported file gives
// the image the exporting application rendered. Standard requests are used
// where RenderMan has them; the rest uses the "micropoly" extensions that
// docs/rib.md ("Writing RIB") describes.
#pragma once

#include <iosfwd>
#include <string>

#include "micropoly/scene.h"

namespace mp {

// Writes `scene` (checked with validate_scene() first; throws mp::Error if it
// is not valid or the stream fails). A non-empty `display_name` adds a Display
// request, so micropoly-render needs no -o. Texture images (Scene::images)
// are written as `image_folder`/<k>.exr (created if missing) and named by
// that path in the RIB; a scene with images needs a folder. Reading such a
// RIB back needs that folder among the reader's allowed folders
// (RibReadOptions) unless it lies inside the scene's folder.
void write_rib(const Scene& scene, std::ostream& out, const std::string& display_name = {},
               const std::string& image_folder = {});

// Same, to a file; throws mp::Error when the file cannot be written. Texture
// images go beside it: scene.rib gets scene_textures/<k>.exr, named relative
// to the RIB file, so the two move together.
void write_rib_file(const Scene& scene, const std::string& path, const std::string& display_name = {});

}  // namespace mp
