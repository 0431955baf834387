#include "cl/build_context.h"

#include <fstream>
#include <regex>
#include <sstream>

namespace mp {

std::string cpu_model_name(const std::string& cpuinfo) {
  std::smatch m;
  static const std::regex line(R"(model name\s*:\s*([^\n]*))");
  if (!std::regex_search(cpuinfo, m, line)) return "";
  std::string name = m[1];
  while (!name.empty() && (name.back() == ' ' || name.back() == '\t' || name.back() == '\r')) name.pop_back();
  return name;
}

std::string pocl_target(const std::string& device_version) {
  // The build hash names the triple, then the CPU: "pthread-<triple>-<cpu>",
  // and a triple has no more than four dash-separated fields.
  std::smatch m;
  static const std::regex hash(R"(HSTR: \w+-x86_64-\w+-\w+-\w+-(\S+))");
  if (std::regex_search(device_version, m, hash)) return m[1];
  return "";
}

std::string build_context(const cl::Device& device) {
  if (!(device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU)) return "driver " + device.getInfo<CL_DRIVER_VERSION>();
  std::ifstream in("/proc/cpuinfo");
  std::stringstream text;
  text << in.rdbuf();
  const std::string model = cpu_model_name(text.str());
  std::string out = "CPU '" + (model.empty() ? std::string("unknown") : model) + "'";
  const std::string platform = cl::Platform(device.getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_VERSION>();
  std::smatch m;
  static const std::regex pocl(R"(PoCL (\S+).*LLVM (\S+?),)");
  if (std::regex_search(platform, m, pocl)) {
    out += ", PoCL " + m[1].str() + " (LLVM " + m[2].str() + ")";
    const std::string target = pocl_target(device.getInfo<CL_DEVICE_VERSION>());
    if (!target.empty()) out += " compiling for " + target;
  } else {
    out += ", " + platform + ", driver " + device.getInfo<CL_DRIVER_VERSION>();
  }
  return out;
}

}  // namespace mp
