// The resolved image's way back to the host, off the frame's critical path:
// its transfers run on the session's transfer queue once the main queue has
// resolved the image, and a worker thread waits for them and copies (or
// converts) the pixels into the result, while the caller goes on to its
// next frame. On a GPU the next frame's kernels run beside the transfer;
// only its resolve waits for the transfer to have read the image buffers.
#pragma once

#include <chrono>
#include <cstdint>
#include <exception>
#include <thread>

#include "cl/device_session.h"
#include "micropoly/render_result.h"
#include "micropoly/scene.h"

namespace mp {

class ResolveStage;
struct FrameSetup;

class ImageReadBack {
 public:
  explicit ImageReadBack(DeviceSession& session);
  // Waits for a read-back in flight (its result must outlive it).
  ~ImageReadBack();
  ImageReadBack(const ImageReadBack&) = delete;
  ImageReadBack& operator=(const ImageReadBack&) = delete;

  // Orders the frame's writes into the image buffers after the last
  // read-back's transfers: call before the frame's first resolve.
  void before_resolve();
  // Starts bringing `resolve`'s image (with Depth and, where kept, Normal
  // when `passes`) into `out` in `format` once the main queue's work so far
  // is done, after finishing the previous read-back. Returns at once; `out`
  // is complete once finish() returns, and must not be touched until then.
  void start(const ResolveStage& resolve, const FrameSetup& frame, bool passes, ReadBack format, RenderResult& out);
  // Waits until the started read-back's pixels are in its result, and
  // rethrows what failed on the way; nothing when none is in flight.
  void finish();
  // Whether the read-back in flight lands in `out`.
  bool lands_in(const RenderResult& out) const { return out_ == &out; }

 private:
  DeviceSession& session_;
  cl::Kernel to_half_;
  cl::Buffer half_;
  size_t half_bytes_ = 0;
  // On discrete GPUs (and for half floats everywhere) the transfers go
  // through one pinned (page-locked) staging buffer, which the driver fills
  // at full bus speed; it grows to the frame read and shrinks where it
  // holds more than four times what a frame needs.
  // Elsewhere the reads land in the result directly.
  bool use_pinned_ = false;
  cl::Buffer pinned_;
  void* pinned_ptr_ = nullptr;
  size_t pinned_bytes_ = 0;
  // The read-back in flight: its transfers, its result, the worker that
  // lands it and what the worker caught.
  cl::Event transferred_;
  RenderResult* out_ = nullptr;
  std::chrono::steady_clock::time_point started_;
  std::thread worker_;
  std::exception_ptr failed_;
};

}  // namespace mp
