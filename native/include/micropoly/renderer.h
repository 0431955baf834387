// The renderer: owns one OpenCL device session (context, queue, built
// program) and renders Scenes into float images. Keep one Renderer alive to
// render many frames without rebuilding kernels.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "micropoly/render_result.h"
#include "micropoly/scene.h"

namespace mp {

struct DeviceInfo {
  int index = 0;             // position in list_devices(), usable as a selector
  std::string name;
  std::string platform;
  std::string type;          // "gpu", "cpu" or "other"
  std::string version;
};

// All OpenCL devices on all platforms, in a stable order.
std::vector<DeviceInfo> list_devices();

// Called between batches with progress in [0, 1]; return false to cancel.
using ProgressCallback = std::function<bool(float progress)>;

class Renderer {
 public:
  // selector: "" (MICROPOLY_DEVICE, else the first GPU, else the first CPU),
  // "cpu", "gpu" or a device index. Throws mp::Error when no device fits or
  // the kernels fail to build.
  explicit Renderer(const std::string& selector = "");
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const DeviceInfo& device() const;
  RenderResult render(const Scene& scene, const ProgressCallback& progress = {});
  // Same, into `out`, reusing its memory: a caller that renders many frames
  // of one size pays for allocating (and faulting in) the image only once.
  void render(const Scene& scene, RenderResult& out, const ProgressCallback& progress = {});

  // For tests of device-failure handling only: plants one OpenCL failure
  // in the coming frames, as the MICROPOLY_CL_FAULT environment variable
  // does when the renderer is created. `plan` is "KIND:N:CODE[:lost][@PHASE]"
  // (native/src/cl/device_faults.h; docs/reliability.md); throws mp::Error
  // when it is malformed.
  void inject_device_fault(const std::string& plan);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mp
