// A device session: the chosen OpenCL device with its context, in-order
// profiling queue and the built Micropoly program (from the binary cache when
// possible).
#pragma once

#include <string>

#include "cl/cl.h"
#include "micropoly/renderer.h"

namespace mp {

// Whether a device of this CL_PLATFORM_VERSION compiles the tile sampler
// (DeviceSession::tile_sampler).
bool compiles_tile_sampler(const std::string& platform_version);

class DeviceSession {
 public:
  explicit DeviceSession(const std::string& selector);

  const DeviceInfo& info() const { return info_; }
  cl::Context& context() { return context_; }
  cl::CommandQueue& queue() { return queue_; }
  cl::Program& program() { return program_; }
  cl::Device& device() { return device_; }
  double program_build_ms() const { return build_ms_; }
  bool program_cache_hit() const { return cache_hit_; }
  size_t max_alloc_bytes() const { return max_alloc_; }
  // Whether the program holds the tile sampler (sample_tiles.cl). PoCL
  // built on LLVM 14 or older (the PoCL binary distribution that CPU-only
  // installs carry) aborts the process compiling its 16-wide vector code,
  // so on such a device it is left out and the per-micropolygon sampler
  // runs instead.
  bool tile_sampler() const { return tile_sampler_; }
  // A read-write device buffer of `bytes` (at least 16); an mp::Error that
  // names `what` when the device cannot hold that much in one buffer.
  cl::Buffer allocate(size_t bytes, const char* what);
  // Makes `buffer` (of `capacity` bytes, kept by the caller) hold at least
  // `bytes`: a new buffer of `bytes` when it is smaller, the old released
  // first and its contents not kept.
  void reserve(cl::Buffer& buffer, size_t& capacity, size_t bytes, const char* what);

 private:
  DeviceInfo info_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  cl::Program program_;
  double build_ms_ = 0;
  bool cache_hit_ = false;
  bool tile_sampler_ = true;
  size_t max_alloc_ = 0;
};

}  // namespace mp
