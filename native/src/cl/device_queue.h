// The command queue every pipeline stage enqueues through: a
// cl::CommandQueue whose enqueue and finish calls first pass the session's
// fault injector (device_faults.h). Callers hold it as DeviceQueue& (a
// cl::CommandQueue& would bypass the check, as these hide, not override).
#pragma once

#include <utility>
#include <vector>

#include "cl/cl.h"
#include "cl/device_faults.h"

namespace mp {

class DeviceQueue : public cl::CommandQueue {
 public:
  DeviceQueue() = default;
  DeviceQueue(const cl::CommandQueue& queue, FaultInjector& faults, const std::vector<const char*>& activities)
      : cl::CommandQueue(queue), faults_(&faults), activities_(&activities) {}

  template <typename... A>
  cl_int enqueueNDRangeKernel(A&&... a) const {
    check(DeviceOp::Launch, "clEnqueueNDRangeKernel");
    return cl::CommandQueue::enqueueNDRangeKernel(std::forward<A>(a)...);
  }
  template <typename... A>
  cl_int enqueueReadBuffer(A&&... a) const {
    check(DeviceOp::Read, "clEnqueueReadBuffer");
    return cl::CommandQueue::enqueueReadBuffer(std::forward<A>(a)...);
  }
  template <typename... A>
  void* enqueueMapBuffer(A&&... a) const {
    check(DeviceOp::Read, "clEnqueueMapBuffer");
    return cl::CommandQueue::enqueueMapBuffer(std::forward<A>(a)...);
  }
  template <typename... A>
  cl_int enqueueWriteBuffer(A&&... a) const {
    check(DeviceOp::Write, "clEnqueueWriteBuffer");
    return cl::CommandQueue::enqueueWriteBuffer(std::forward<A>(a)...);
  }
  template <typename... A>
  cl_int enqueueFillBuffer(A&&... a) const {
    check(DeviceOp::Write, "clEnqueueFillBuffer");
    return cl::CommandQueue::enqueueFillBuffer(std::forward<A>(a)...);
  }
  template <typename... A>
  cl_int enqueueCopyBuffer(A&&... a) const {
    check(DeviceOp::Write, "clEnqueueCopyBuffer");
    return cl::CommandQueue::enqueueCopyBuffer(std::forward<A>(a)...);
  }
  cl_int finish() const {
    check(DeviceOp::Finish, "clFinish");
    return cl::CommandQueue::finish();
  }
  // Waits for the queue without the fault check and without throwing: for
  // cleaning up after a failure, when host memory that queued transfers
  // point into is about to be freed.
  void drain() const noexcept { ::clFinish((*this)()); }

 private:
  void check(DeviceOp op, const char* call) const {
    if (faults_ && faults_->armed()) faults_->hit(op, call, activities_->empty() ? "" : activities_->back());
  }
  FaultInjector* faults_ = nullptr;
  const std::vector<const char*>* activities_ = nullptr;
};

}  // namespace mp
