#include "cl/device_faults.h"

#include <cstdlib>
#include <new>

#include "micropoly/error.h"

namespace mp {
namespace {

DeviceOp parse_op(const std::string& kind, const std::string& text) {
  if (kind == "alloc") return DeviceOp::Alloc;
  if (kind == "launch") return DeviceOp::Launch;
  if (kind == "read") return DeviceOp::Read;
  if (kind == "write") return DeviceOp::Write;
  if (kind == "finish") return DeviceOp::Finish;
  throw Error("device fault plan '" + text + "': unknown operation '" + kind +
              "' (alloc, launch, read, write or finish)");
}

cl_int parse_code(const std::string& name, const std::string& text) {
  static const cl_int known[] = {CL_OUT_OF_RESOURCES,     CL_MEM_OBJECT_ALLOCATION_FAILURE,
                                 CL_OUT_OF_HOST_MEMORY,   CL_INVALID_COMMAND_QUEUE,
                                 CL_DEVICE_NOT_AVAILABLE, CL_INVALID_CONTEXT,
                                 CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST};
  for (cl_int code : known)
    if (name == cl_error_name(code)) return code;
  char* end = nullptr;
  const long number = std::strtol(name.c_str(), &end, 10);
  if (!name.empty() && end && *end == '\0' && number < 0) return static_cast<cl_int>(number);
  throw Error("device fault plan '" + text + "': unknown OpenCL error '" + name + "'");
}

}  // namespace

FaultPlan parse_fault_plan(const std::string& text) {
  FaultPlan plan;
  std::string body = text;
  if (const size_t at = body.find('@'); at != std::string::npos) {
    plan.activity = body.substr(at + 1);
    body = body.substr(0, at);
  }
  std::string fields[4];
  int count = 0;
  size_t start = 0;
  while (count < 4) {
    const size_t colon = body.find(':', start);
    fields[count++] = body.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (colon == std::string::npos) break;
    start = colon + 1;
    if (count == 4) throw Error("device fault plan '" + text + "': too many fields");
  }
  if (count < 3) throw Error("device fault plan '" + text + "': expected KIND:N:CODE[:lost][@ACTIVITY]");
  plan.op = parse_op(fields[0], text);
  char* end = nullptr;
  plan.nth = std::strtol(fields[1].c_str(), &end, 10);
  if (fields[1].empty() || !end || *end != '\0' || plan.nth < 1)
    throw Error("device fault plan '" + text + "': N must be a positive count");
  plan.host = fields[2] == "host";
  plan.code = plan.host ? CL_OUT_OF_HOST_MEMORY : parse_code(fields[2], text);
  if (count == 4) {
    if (fields[3] != "lost") throw Error("device fault plan '" + text + "': the fourth field can only be 'lost'");
    plan.lost = true;
  }
  plan.lost = plan.lost || cl_error_means_device_lost(plan.code);
  return plan;
}

void FaultInjector::arm(const FaultPlan& plan) {
  plan_ = plan;
  seen_ = 0;
  fired_ = dead_ = false;
  armed_ = true;
}

void FaultInjector::hit(DeviceOp op, const char* call, const char* activity) {
  if (dead_) throw cl::Error(plan_->code, call);
  if (fired_ || op != plan_->op) return;
  if (!plan_->activity.empty() && plan_->activity != activity) return;
  if (++seen_ < plan_->nth) return;
  fired_ = true;
  dead_ = plan_->lost;
  armed_ = dead_;  // a spent one-shot plan costs nothing any more
  if (plan_->host) throw std::bad_alloc();
  throw cl::Error(plan_->code, call);
}

FaultInjector FaultInjector::reopened() const {
  FaultInjector next = *this;
  next.dead_ = false;
  next.armed_ = plan_ && !fired_;
  return next;
}

}  // namespace mp
