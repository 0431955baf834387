// A 64-bit fingerprint of everything in a Scene that the uploaded scene
// buffers (HostSceneData) depend on: geometry, transforms, the camera's
// placement, materials, lights and images. Resolution, samples, shading rate
// and the other settings do not enter, so re-rendering a scene at another
// sample count or size (progressive viewport passes, repeated frames) can
// reuse the buffers already on the device.
#pragma once

#include <cstdint>

#include "micropoly/scene.h"

namespace mp {

uint64_t scene_fingerprint(const Scene& scene);

}  // namespace mp
