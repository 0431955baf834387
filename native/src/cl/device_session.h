// A device session: the chosen OpenCL device with its context, in-order
// profiling queue and the built Micropoly program (from the program cache when
// possible: program_cache.h).
#pragma once

#include <string>
#include <vector>

#include "cl/cl.h"
#include "cl/device_faults.h"
#include "cl/device_queue.h"
#include "micropoly/renderer.h"

namespace mp {

// Whether a device of this CL_PLATFORM_VERSION compiles the tile sampler
// (DeviceSession::tile_sampler).
bool compiles_tile_sampler(const std::string& platform_version);

class DeviceSession {
 public:
  // Arms the fault injector from MICROPOLY_CL_FAULT when it is set
  // (device_faults.h; tests only).
  explicit DeviceSession(const std::string& selector);
  // A session that carries on `faults` (FaultInjector::reopened) instead of
  // reading the environment: the renderer reopening a lost device.
  DeviceSession(const std::string& selector, const FaultInjector& faults);
  DeviceSession(const DeviceSession&) = delete;
  DeviceSession& operator=(const DeviceSession&) = delete;

  const DeviceInfo& info() const { return info_; }
  cl::Context& context() { return context_; }
  DeviceQueue& queue() { return queue_; }
  // A second in-order queue for the image's read-back, so that its transfer
  // overlaps the next frame's kernels (on a GPU the copy engine runs beside
  // the compute units); the two queues order their work through events.
  DeviceQueue& transfer_queue() { return transfer_queue_; }
  cl::Program& program() { return program_; }
  cl::Device& device() { return device_; }
  double program_build_ms() const { return build_ms_; }
  bool program_cache_hit() const { return cache_hit_; }
  size_t max_alloc_bytes() const { return max_alloc_; }
  // A number no earlier call returned: names one upload of scene data, so a
  // kernel knows whether the buffers it holds are still the scene's
  // (scene_kernel.h).
  uint64_t next_data_version() { return ++data_versions_; }
  // Whether the program holds the tile sampler (sample_tiles.cl). PoCL
  // built on LLVM 14 or older (e.g. PyPI's pocl-binary-distribution 3.0)
  // aborts the process compiling its 16-wide vector code, so on such a
  // device it is left out and the per-micropolygon sampler runs instead.
  bool tile_sampler() const { return tile_sampler_; }
  // A read-write device buffer of `bytes` (at least 16); an mp::Error that
  // names `what` when the device cannot hold that much in one buffer.
  cl::Buffer allocate(size_t bytes, const char* what, cl_mem_flags flags = CL_MEM_READ_WRITE);
  // Makes `buffer` (of `capacity` bytes, kept by the caller) hold at least
  // `bytes`: a new buffer of `bytes` when it is smaller, the old released
  // first and its contents not kept.
  void reserve(cl::Buffer& buffer, size_t& capacity, size_t bytes, const char* what);

  // A named phase of a frame ("upload", "dice", ...) for as long as it
  // lives; phases nest. When an exception leaves the innermost phase, its
  // path ("shadows/bound_split") is kept as failed_activity() for the error
  // message, and fault plans can target a phase by name.
  class Activity {
   public:
    Activity(DeviceSession& session, const char* name);
    ~Activity();
    Activity(const Activity&) = delete;
    Activity& operator=(const Activity&) = delete;

   private:
    DeviceSession& session_;
    int uncaught_;
  };
  const std::string& failed_activity() const { return failed_activity_; }
  void clear_failed_activity() { failed_activity_.clear(); }

  // Whether the device still answers: a small write, read back and
  // compared, after a frame failed with an error that may have been a
  // device fault in disguise (cl_error_means_out_of_memory).
  bool responds();

  FaultInjector& faults() { return faults_; }
  // The queue's launches and the host's waits on the device
  // (queue_counts.h); the renderer resets them at each frame's start and
  // reports them in its stats.
  QueueCounts& queue_counts() { return queue_counts_; }

 private:
  void open(const std::string& selector);

  DeviceInfo info_;
  cl::Device device_;
  cl::Context context_;
  FaultInjector faults_;
  std::vector<const char*> activities_;
  QueueCounts queue_counts_;
  std::string failed_activity_;
  DeviceQueue queue_;
  DeviceQueue transfer_queue_;
  cl::Program program_;
  double build_ms_ = 0;
  bool cache_hit_ = false;
  bool tile_sampler_ = true;
  size_t max_alloc_ = 0;
  uint64_t data_versions_ = 0;
};

}  // namespace mp
