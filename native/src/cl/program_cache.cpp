#include "cl/program_cache.h"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "cl/build_context.h"
#include "cl/embedded_kernels.h"
#include "micropoly/error.h"

namespace fs = std::filesystem;

namespace mp {
namespace {

std::string expand_includes(const std::string& text, const std::map<std::string, std::string>& files, int depth) {
  if (depth > 16) throw Error("kernel sources: #include nesting too deep");
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    auto pos = line.find("#include \"");
    if (pos != std::string::npos && line.find_first_not_of(" \t") == pos) {
      auto start = pos + 10, end = line.find('"', start);
      std::string name = line.substr(start, end - start);
      auto it = files.find(name);
      if (it == files.end()) throw Error("kernel sources: missing embedded header " + name);
      out += expand_includes(it->second, files, depth + 1);
    } else {
      out += line;
      out += '\n';
    }
  }
  return out;
}

std::uint64_t fnv1a(const std::string& s, std::uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

fs::path cache_dir() {
  if (const char* d = std::getenv("MICROPOLY_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return fs::path(d) / "micropoly";
  if (const char* d = std::getenv("HOME"); d && *d) return fs::path(d) / ".cache" / "micropoly";
  return {};
}

// Whether the driver keeps compiled programs itself, so that Micropoly keeps
// only a record that it built this source. PoCL does (its kernel cache, on
// unless POCL_KERNEL_CACHE=0: the program's bitcode by source, then every
// kernel's code per launch shape as it first runs). Asking PoCL for a binary
// (CL_PROGRAM_BINARIES) makes it compile a generic variant of every kernel in
// the program first, launched or not: that doubled a cold build of the
// stages' program (about 36 s against 18 s for a first render on 2 cores),
// while a later session found everything in PoCL's cache either way.
bool driver_caches_programs(const cl::Device& device) {
  const std::string platform = cl::Platform(device.getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_NAME>();
  if (platform.find("Portable Computing Language") == std::string::npos) return false;
  const char* cache = std::getenv("POCL_KERNEL_CACHE");
  return !(cache && std::string(cache) == "0");
}

std::string build_log(const cl::Program& program, const cl::Device& device) {
  try {
    return program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
  } catch (const cl::Error&) {
    return "";
  }
}

}  // namespace

std::string first_build_error(const std::string& log) {
  // Compilers name the place as "FILE:LINE:COL:" (clang puts "error:" after
  // it, PoCL before it); FILE is a temporary name that means nothing to the
  // reader, so it becomes "line LINE:COL:".
  static const std::regex place(R"(([^\s:]+):(\d+):(\d+):)");
  std::string first;
  size_t errors = 0;
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("error:") == std::string::npos) continue;
    if (errors++ == 0) first = std::regex_replace(line, place, "line $2:$3:", std::regex_constants::format_first_only);
  }
  if (errors == 0) {
    first = log.substr(0, log.find('\n'));
    if (first.empty()) return "no compiler log";
  }
  if (first.size() > 300) first = first.substr(0, 300) + "...";
  if (errors > 1) first += " (and " + std::to_string(errors - 1) + " more)";
  return first;
}

std::map<std::string, std::string> embedded_files() {
  std::map<std::string, std::string> files;
  for (int i = 0; i < kEmbeddedKernelFileCount; ++i) files[kEmbeddedKernelFiles[i].name] = kEmbeddedKernelFiles[i].source;
  return files;
}

std::string assemble_program_source() {
  const std::map<std::string, std::string> files = embedded_files();
  std::string source;
  for (const auto& [name, text] : files) {
    // The stages' kernels only: the other folders hold headers and the
    // material programs (built apart, program_cache.h).
    if (name.rfind("stages/", 0) == 0 && name.size() > 3 && name.compare(name.size() - 3, 3, ".cl") == 0) {
      source += "/* ---- " + name + " ---- */\n";
      source += expand_includes(text, files, 0);
    }
  }
  return source;
}

std::vector<std::string> material_program_switches(const std::string& generated) {
  std::vector<std::string> switches;
  for (size_t line = 0; line < generated.size();) {
    size_t end = generated.find('\n', line);
    if (end == std::string::npos) end = generated.size();
    if (generated.compare(line, 21, "#define MP_NODE_USES_") == 0) switches.push_back(generated.substr(line, end - line));
    line = end + 1;
  }
  return switches;
}

std::string assemble_light_program_source(bool thin_film) {
  const std::map<std::string, std::string> files = embedded_files();
  const std::string switches = thin_film ? "#define MP_NODE_USES_THIN_FILM 1\n" : "";
  return expand_includes(switches + files.at("materials/light_program.cl"), files, 0);
}

std::string assemble_material_program_source(const std::string& generated, bool world) {
  std::map<std::string, std::string> files = embedded_files();
  const std::string marker = "/* @MATERIAL_PROGRAM_SOURCE@ */";
  std::string text = files.at("materials/material_program.cl");
  const size_t at = text.find(marker);
  if (at == std::string::npos) throw Error("kernel sources: material program marker missing");
  text.replace(at, marker.size(), generated);
  // Switches the generated code sets for the kernel headers
  // ("#define MP_NODE_USES_..." lines) go ahead of them.
  std::string switches;
  for (const std::string& line : material_program_switches(generated)) switches += line + "\n";
  if (world) switches += "#define MP_WORLD_PROGRAM 1\n";
  return expand_includes(switches + text, files, 0);
}

BuiltProgram build_program_cached(const cl::Context& context, const cl::Device& device, const std::string& source,
                                  const std::string& options) {
  auto t0 = std::chrono::steady_clock::now();
  std::string identity = device.getInfo<CL_DEVICE_NAME>() + "|" + device.getInfo<CL_DEVICE_VERSION>() + "|" +
                         device.getInfo<CL_DRIVER_VERSION>() + "|" +
                         cl::Platform(device.getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_NAME>() + "|" + options;
  char key[32];
  std::snprintf(key, sizeof key, "%016llx", static_cast<unsigned long long>(fnv1a(source, fnv1a(identity))));
  fs::path dir = cache_dir();
  // Where the driver caches programs itself, the entry is a record of the
  // build (its identity), not a binary (driver_caches_programs).
  const bool record_only = driver_caches_programs(device);
  fs::path file = dir.empty() ? fs::path() : dir / (std::string(key) + (record_only ? ".built" : ".bin"));
  std::vector<cl::Device> devices{device};
  auto elapsed = [&] { return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(); };
  auto write_atomically = [&](const char* data, size_t size) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    fs::path tmp = file;
    tmp += ".tmp" + std::to_string(::getpid());
    {
      std::ofstream out(tmp, std::ios::binary);
      out.write(data, static_cast<std::streamsize>(size));
    }
    fs::rename(tmp, file, ec);  // atomic: concurrent renders never read half a file
    if (ec) fs::remove(tmp, ec);
  };
  const std::string record = identity + "|" + key + "\n";

  if (!file.empty() && !record_only) {
    std::ifstream in(file, std::ios::binary);
    std::vector<unsigned char> binary((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!binary.empty()) {
      try {
        cl::Program::Binaries binaries{binary};
        cl::Program program(context, devices, binaries);
        program.build(devices, options.c_str());
        return {program, true, elapsed()};
      } catch (const cl::Error&) {
        // A stale or foreign binary: fall through and rebuild from source.
      }
    }
  }

  cl::Program program(context, source);
  try {
    program.build(devices, options.c_str());
  } catch (const cl::Error& e) {
    // One line for the artist (Blender's report, the CLI): the compiler's
    // first error; the whole log goes next to the cached binaries.
    const std::string log = build_log(program, device);
    std::string where;
    if (!file.empty()) {
      std::error_code ec;
      fs::create_directories(dir, ec);
      fs::path log_file = dir / (std::string(key) + ".log");
      std::ofstream out(log_file);
      out << log;
      if (out) where = " (compiler log: " + log_file.string() + ")";
    }
    throw Error("the OpenCL kernels failed to build on " + device.getInfo<CL_DEVICE_NAME>() + " (" +
                build_context(device) + "): " +
                first_build_error(log) + where);
  }
  bool built_before = false;
  if (!file.empty() && record_only) {
    // The driver found its own cached build of this source, or made one;
    // the record says whether this source was built here before.
    std::ifstream in(file, std::ios::binary);
    built_before = std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()) == record;
    if (!built_before) {
      try {
        write_atomically(record.data(), record.size());
      } catch (const std::exception&) {
        // The record is an optimisation only.
      }
    }
  } else if (!file.empty()) {
    try {
      auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
      if (!binaries.empty() && !binaries[0].empty())
        write_atomically(reinterpret_cast<const char*>(binaries[0].data()), binaries[0].size());
    } catch (const std::exception&) {
      // The cache is an optimisation only.
    }
  }
  return {program, built_before, elapsed()};
}

}  // namespace mp
