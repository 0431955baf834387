// Device-fault injection: makes one chosen OpenCL operation of a frame fail
// with the error a driver raises when the device runs out of memory or is
// lost, so the renderer's recovery can be tested on any device (PoCL never
// fails these ways on its own). Armed only by tests: through
// MICROPOLY_CL_FAULT, read when a DeviceSession opens, or
// Renderer::inject_device_fault. Unarmed, a check is one predictable branch.
#pragma once

#include <optional>
#include <string>

#include "cl/cl.h"

namespace mp {

// The kinds of checked operations (DeviceSession::allocate, DeviceQueue).
// Write covers writes, fills and copies; Read covers reads and maps.
enum class DeviceOp { Alloc, Launch, Read, Write, Finish };

// "KIND:N:CODE[:lost][@ACTIVITY]": the Nth operation of KIND (alloc, launch,
// read, write, finish), counted from when the plan is armed and only while
// the innermost activity (DeviceSession::Activity) is ACTIVITY when one is
// given, fails with CODE (an OpenCL error name such as CL_OUT_OF_RESOURCES,
// or its number), or with CODE "host" throws std::bad_alloc, as the host's
// allocator does when the computer runs out of memory there. Device-lost codes (cl_error_means_device_lost), and any
// code marked `lost`, also make every later operation of that session fail
// with the same code, as a context whose device fell off the bus does.
struct FaultPlan {
  DeviceOp op = DeviceOp::Launch;
  long nth = 1;
  cl_int code = CL_OUT_OF_RESOURCES;
  bool lost = false;
  bool host = false;     // std::bad_alloc rather than an OpenCL error
  std::string activity;  // empty: any
};

// Parses a plan; an mp::Error names what is wrong with a malformed one.
FaultPlan parse_fault_plan(const std::string& text);

class FaultInjector {
 public:
  void arm(const FaultPlan& plan);
  bool armed() const { return armed_; }
  // Throws the planned cl::Error (named after the OpenCL call `call`) when
  // this operation is the planned one, or when a lost-device fault fired.
  void hit(DeviceOp op, const char* call, const char* activity);
  // Whether the plan has fired.
  bool fired() const { return fired_; }
  // The same plan state for a freshly opened device: a fired plan stays
  // spent, and the lost device's failures stop.
  FaultInjector reopened() const;

 private:
  std::optional<FaultPlan> plan_;
  long seen_ = 0;
  bool armed_ = false;
  bool fired_ = false;
  bool dead_ = false;
};

}  // namespace mp
