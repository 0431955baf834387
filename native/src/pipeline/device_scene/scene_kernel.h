// A kernel that reads the scene: its first arguments are the scene's data
// (kernels/core/mp_scene_data.h, MP_SCENE_PARAMS), bound by that list once
// for each upload of it, not per launch; a launch binds only its batch and
// its own arguments after them. Move-only: the record of what is bound
// belongs to one kernel object.
#pragma once

#include <cstdint>

#include "cl/cl.h"
#include "cl/kernel_args.h"
#include "pipeline/device_scene/scene_buffers.h"

namespace mp {

// How many arguments the scene's data takes.
#define MP_COUNT_SCENE_ENTRY(type, name) +1
inline constexpr cl_uint kSceneDataArgs = 0 MP_SCENE_DATA(MP_COUNT_SCENE_ENTRY, MP_COUNT_SCENE_ENTRY);
#undef MP_COUNT_SCENE_ENTRY

// Binds the scene's data to `kernel`'s first kSceneDataArgs arguments.
void bind_scene_data(cl::Kernel& kernel, const SceneBuffers& scene);

class SceneKernel {
 public:
  SceneKernel() = default;
  SceneKernel(const cl::Program& program, const char* name) : kernel_(program, name) {}
  SceneKernel(SceneKernel&& other) noexcept : kernel_(std::move(other.kernel_)), bound_(other.bound_) {
    other.bound_ = 0;
  }
  SceneKernel& operator=(SceneKernel&& other) noexcept {
    kernel_ = std::move(other.kernel_);
    bound_ = other.bound_;
    other.bound_ = 0;
    return *this;
  }
  SceneKernel(const SceneKernel&) = delete;
  SceneKernel& operator=(const SceneKernel&) = delete;

  // The kernel with `scene` bound (again only if its buffers changed since)
  // and `args` after it, ready to enqueue.
  template <typename... Args>
  cl::Kernel& bind(const SceneBuffers& scene, const Args&... args) {
    if (scene.version == 0 || bound_ != scene.version) {
      bind_scene_data(kernel_, scene);
      bound_ = scene.version;
    }
    bind_args_from(kernel_, kSceneDataArgs, args...);
    return kernel_;
  }
  cl::Kernel& kernel() { return kernel_; }

 private:
  cl::Kernel kernel_;
  uint64_t bound_ = 0;  // SceneBuffers::version last bound; 0: none
};

}  // namespace mp
