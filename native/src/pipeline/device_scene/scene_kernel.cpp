#include "pipeline/device_scene/scene_kernel.h"

namespace mp {

void bind_scene_data(cl::Kernel& kernel, const SceneBuffers& scene) {
  // The list's entries in its order, from argument 0 (kernel_args.h numbers them).
#define MP_SCENE_ENTRY_VALUE(type, name) , scene.name
  bind_args_from(kernel, 0 MP_SCENE_DATA(MP_SCENE_ENTRY_VALUE, MP_SCENE_ENTRY_VALUE));
#undef MP_SCENE_ENTRY_VALUE
}

}  // namespace mp
