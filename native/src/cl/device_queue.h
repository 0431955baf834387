// The command queue every pipeline stage enqueues through: a
// cl::CommandQueue whose enqueue and finish calls first pass the session's
// fault injector (device_faults.h), and whose launches and calls that hold
// the host until the device is done are counted (queue_counts.h). Callers
// hold it as DeviceQueue& (a cl::CommandQueue& would bypass both, as these
// hide, not override).
#pragma once

#include <utility>
#include <vector>

#include "cl/cl.h"
#include "cl/device_faults.h"
#include "cl/queue_counts.h"

namespace mp {

class DeviceQueue : public cl::CommandQueue {
 public:
  DeviceQueue() = default;
  DeviceQueue(const cl::CommandQueue& queue, FaultInjector& faults, const std::vector<const char*>& activities,
              QueueCounts& counts)
      : cl::CommandQueue(queue), faults_(&faults), activities_(&activities), counts_(&counts) {}

  template <typename... A>
  cl_int enqueueNDRangeKernel(A&&... a) const {
    check(DeviceOp::Launch, "clEnqueueNDRangeKernel");
    if (counts_) counts_->launches.note(*activities_);
    return cl::CommandQueue::enqueueNDRangeKernel(std::forward<A>(a)...);
  }
  template <typename... A>
  cl_int enqueueReadBuffer(const cl::Buffer& buffer, cl_bool blocking, A&&... a) const {
    check(DeviceOp::Read, "clEnqueueReadBuffer");
    if (blocking) waited();
    return cl::CommandQueue::enqueueReadBuffer(buffer, blocking, std::forward<A>(a)...);
  }
  template <typename... A>
  void* enqueueMapBuffer(const cl::Buffer& buffer, cl_bool blocking, A&&... a) const {
    check(DeviceOp::Read, "clEnqueueMapBuffer");
    if (blocking) waited();
    return cl::CommandQueue::enqueueMapBuffer(buffer, blocking, std::forward<A>(a)...);
  }
  template <typename... A>
  cl_int enqueueWriteBuffer(const cl::Buffer& buffer, cl_bool blocking, A&&... a) const {
    check(DeviceOp::Write, "clEnqueueWriteBuffer");
    if (blocking) waited();
    return cl::CommandQueue::enqueueWriteBuffer(buffer, blocking, std::forward<A>(a)...);
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
    waited();
    return cl::CommandQueue::finish();
  }
  // Waits for `event`, one of this queue's commands.
  void wait(const cl::Event& event) const {
    waited();
    event.wait();
  }
  // Waits for the queue without the fault check and without throwing: for
  // cleaning up after a failure, when host memory that queued transfers
  // point into is about to be freed.
  void drain() const noexcept { ::clFinish((*this)()); }

 private:
  void check(DeviceOp op, const char* call) const {
    if (faults_ && faults_->armed()) faults_->hit(op, call, activities_->empty() ? "" : activities_->back());
  }
  void waited() const {
    if (counts_) counts_->waits.note(*activities_);
  }
  FaultInjector* faults_ = nullptr;
  const std::vector<const char*>* activities_ = nullptr;
  QueueCounts* counts_ = nullptr;
};

}  // namespace mp
