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
  // Frames in a loop (the CLI's --repeat): returns once the frame is
  // resolved on the device and its pixels are on their way to `out`, so the
  // caller's next frame runs beside their transfer and copy
  // (docs/pipeline.md, step 8). `out` is complete, with its stats, once
  // finish_frame() returns or the next render of either kind has started its
  // own read-back; until then it must stay alive and untouched, so a loop
  // alternates between two results. A failure on the way is thrown by
  // whichever of those calls waits for it.
  void render_overlapped(const Scene& scene, RenderResult& out, const ProgressCallback& progress = {});
  // Waits for the last render_overlapped frame's pixels (nothing if none).
  void finish_frame();

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
