// Scene validation fuzz target: the Python module hands the pipeline whatever
// arrays Blender's add-on (or a script) puts into a Scene, and
// mp::validate_scene is what stands between them and the pipeline
// (scene.h: "the pipeline never sees NaNs or bad indices"). Each input is
// decoded into a Scene (scene_decoder.h); when validation accepts it, the
// host-side preparation every render starts with runs on it
// (prepare_scene_data: OpenSubdiv refinement, polygon and Bezier patches,
// shared edges, materials, lights and images in their device layout).
// Validation may refuse with mp::Error and preparation may too (OpenSubdiv
// rejecting a topology); a crash, sanitizer report, other exception or hang
// after validation accepted is the bug this target looks for.
#include <cstddef>
#include <cstdint>

#include <fuzzer/FuzzedDataProvider.h>

#include "fuzz_support.h"
#include "micropoly/error.h"
#include "pipeline/device_scene/scene_buffers.h"
#include "scene_decoder.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mp::fuzz::planted_bug(data, size);
  FuzzedDataProvider in(data, size);
  const mp::Scene scene = mp::fuzz::decode_scene(in);
  try {
    mp::validate_scene(scene);
  } catch (const mp::Error&) {
    return 0;
  }
  try {
    const mp::HostSceneData host = mp::prepare_scene_data(scene);
    // Every patch refers to a material the scene has (or the default one).
    const size_t materials = host.materials.size();
    for (const glm::uvec4& info : host.patches.info)
      if (materials > 0 && info.y >= materials) __builtin_trap();
  } catch (const mp::Error&) {
  }
  return 0;
}
