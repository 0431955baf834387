// Kernels are embedded at build time, built once per device and cached on
// disk; a kernel that fails to build gives a clear error.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "cl/build_context.h"
#include "cl/device_session.h"
#include "cl/program_cache.h"
#include "micropoly/error.h"

namespace mp {
namespace {

class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_)
      setenv(name_, old_.c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

std::filesystem::path fresh_dir(const char* name) {
  auto dir = std::filesystem::temp_directory_path() / (std::string(name) + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(ProgramCache, SecondSessionLoadsTheCachedBinary) {
  auto dir = fresh_dir("micropoly-cache-test-");
  ScopedEnv env("MICROPOLY_CACHE_DIR", dir.string());
  DeviceSession first("");
  EXPECT_FALSE(first.program_cache_hit());
  ASSERT_TRUE(std::filesystem::exists(dir));
  EXPECT_FALSE(std::filesystem::is_empty(dir));
  DeviceSession second("");
  EXPECT_TRUE(second.program_cache_hit());
  std::filesystem::remove_all(dir);
}

TEST(ProgramCache, CorruptCacheEntriesAreRebuilt) {
  auto dir = fresh_dir("micropoly-cache-corrupt-");
  ScopedEnv env("MICROPOLY_CACHE_DIR", dir.string());
  { DeviceSession warm(""); }
  for (auto& entry : std::filesystem::directory_iterator(dir)) {
    std::FILE* f = std::fopen(entry.path().c_str(), "wb");
    std::fputs("not a program binary", f);
    std::fclose(f);
  }
  DeviceSession session("");
  EXPECT_FALSE(session.program_cache_hit());
  std::filesystem::remove_all(dir);
}

// PoCL keeps compiled programs in its own kernel cache; asking it for a
// binary would make it compile every kernel's generic variant first. There
// Micropoly's entry is only a record of the build; elsewhere (and on PoCL
// with its cache off) the binary itself, which a second build loads.
TEST(ProgramCache, PoclKeepsARecordOtherDriversTheBinary) {
  DeviceSession session("");
  const std::string platform =
      cl::Platform(session.device().getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_NAME>();
  const bool pocl = platform.find("Portable Computing Language") != std::string::npos;
  // A source no cache holds yet.
  const std::string source = "__kernel void one(__global float* x) { x[0] = " + std::to_string(::getpid()) +
                             ".0f; }\n__kernel void two(__global float* x) { x[1] = 2.0f; }\n";
  auto entries = [](const std::filesystem::path& dir, const std::string& ext) {
    int n = 0;
    if (std::filesystem::exists(dir))
      for (auto& e : std::filesystem::directory_iterator(dir)) n += e.path().extension() == ext;
    return n;
  };
  for (const char* kernel_cache : {"1", "0"}) {
    auto dir = fresh_dir(kernel_cache[0] == '1' ? "micropoly-cache-record-" : "micropoly-cache-binary-");
    ScopedEnv env("MICROPOLY_CACHE_DIR", dir.string());
    ScopedEnv pocl_env("POCL_KERNEL_CACHE", kernel_cache);
    const bool record = pocl && kernel_cache[0] == '1';
    BuiltProgram first = build_program_cached(session.context(), session.device(), source, "-cl-std=CL1.2");
    EXPECT_FALSE(first.from_cache);
    EXPECT_EQ(entries(dir, ".built"), record ? 1 : 0) << platform << " POCL_KERNEL_CACHE=" << kernel_cache;
    EXPECT_EQ(entries(dir, ".bin"), record ? 0 : 1) << platform << " POCL_KERNEL_CACHE=" << kernel_cache;
    BuiltProgram second = build_program_cached(session.context(), session.device(), source, "-cl-std=CL1.2");
    EXPECT_TRUE(second.from_cache);
    // Either way the program runs.
    cl::Buffer x(session.context(), CL_MEM_READ_WRITE, 2 * sizeof(float));
    cl::Kernel one(second.program, "one");
    one.setArg(0, x);
    cl::CommandQueue queue(session.context(), session.device());
    queue.enqueueNDRangeKernel(one, cl::NullRange, cl::NDRange(1));
    float got[2] = {0, 0};
    queue.enqueueReadBuffer(x, CL_TRUE, 0, sizeof got, got);
    EXPECT_EQ(got[0], static_cast<float>(::getpid()));
    // A record of another identity (a foreign or older entry) is no hit.
    if (record) {
      for (auto& e : std::filesystem::directory_iterator(dir)) {
        std::ofstream out(e.path(), std::ios::trunc);
        out << "another device|0000\n";
      }
      EXPECT_FALSE(build_program_cached(session.context(), session.device(), source, "-cl-std=CL1.2").from_cache);
    }
    std::filesystem::remove_all(dir);
  }
}

TEST(ProgramCache, KernelBuildFailureIsAClearError) {
  DeviceSession session("");
  try {
    build_program_cached(session.context(), session.device(), "__kernel void broken(__global float* x) { x[0] = y; }",
                         "-cl-std=CL1.2");
    FAIL() << "expected a build error";
  } catch (const Error& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("failed to build"), std::string::npos) << msg;
    EXPECT_NE(msg.find("line 1:"), std::string::npos) << msg;  // where, in the source as built
    EXPECT_NE(msg.find("'y'"), std::string::npos) << msg;     // what: the undeclared name
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line for Blender's report: " << msg;
    // On a CPU, which processor and what its compiler built for.
    if (session.device().getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) {
      std::ifstream in("/proc/cpuinfo");
      std::stringstream cpuinfo;
      cpuinfo << in.rdbuf();
      const std::string model = cpu_model_name(cpuinfo.str());
      EXPECT_FALSE(model.empty());
      EXPECT_NE(msg.find("CPU '" + model + "'"), std::string::npos) << msg;
      const std::string target = pocl_target(session.device().getInfo<CL_DEVICE_VERSION>());
      if (!target.empty()) EXPECT_NE(msg.find("compiling for " + target), std::string::npos) << msg;
    }
  }
}

TEST(ProgramCache, BuildContextReadsTheProcessorAndPoclsTarget) {
  const std::string cpuinfo =
      "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 26\nmodel name\t: AMD EPYC 9755 128-Core Processor  \n"
      "flags\t\t: fpu avx512f\n\nprocessor\t: 1\nmodel name\t: other\n";
  EXPECT_EQ(cpu_model_name(cpuinfo), "AMD EPYC 9755 128-Core Processor");
  EXPECT_EQ(cpu_model_name("processor\t: 0\n"), "");
  EXPECT_EQ(pocl_target("OpenCL 3.0 PoCL HSTR: pthread-x86_64-pc-linux-gnu-skylake-avx512"), "skylake-avx512");
  EXPECT_EQ(pocl_target("OpenCL 3.0 PoCL HSTR: pthread-x86_64-unknown-linux-gnu-generic"), "generic");
  EXPECT_EQ(pocl_target("OpenCL 3.0 CUDA"), "");
}

TEST(ProgramCache, FirstBuildErrorIsOneLineWithoutTheTemporaryFileName) {
  const std::string log =
      "/tmp/pocl-abc/input.cl:12:7: warning: unused variable 'q'\n"
      "/tmp/pocl-abc/input.cl:40:3: error: use of undeclared identifier 'y'\n  x = y;\n    ^\n"
      "/tmp/pocl-abc/input.cl:41:1: error: expected ';'\n2 errors generated.\n";
  EXPECT_EQ(first_build_error(log), "line 40:3: error: use of undeclared identifier 'y' (and 1 more)");
  // PoCL's order: "error:" first.
  EXPECT_EQ(first_build_error("error: /root/.cache/pocl/kcache/tempfile_x.cl:1:50: use of undeclared identifier 'y'\n"),
            "error: line 1:50: use of undeclared identifier 'y'");
  EXPECT_EQ(first_build_error("ptxas fatal: out of registers\nmore\n"), "ptxas fatal: out of registers");
  EXPECT_EQ(first_build_error(""), "no compiler log");
}

TEST(ProgramCache, EmbeddedSourcesResolveEveryInclude) {
  std::string source = assemble_program_source();
  EXPECT_EQ(source.find("#include \""), std::string::npos);
  for (const char* kernel : {"bs_bounded_step", "bs_breadth_classify", "scan_blocks", "dice_grids", "shade_grids",
                             "sample_micropolygons", "resolve_pixels"})
    EXPECT_NE(source.find(kernel), std::string::npos) << kernel;
}

// A material program's switches for the kernel headers ("#define
// MP_NODE_USES_...") reach them: they go ahead of the headers, so the thin
// film's code is in a program that asks for it and in no other.
TEST(ProgramCache, MaterialProgramSwitchesPrecedeTheHeaders) {
  const std::string body = "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {}\n";
  const std::string with = assemble_material_program_source("#define MP_NODE_USES_THIN_FILM 1\n" + body);
  const std::string without = assemble_material_program_source(body);
  EXPECT_LT(with.find("#define MP_NODE_USES_THIN_FILM 1"), with.find("#ifndef MP_CLOSURES_H"));
  EXPECT_NE(with.find("mp_film_dielectric"), std::string::npos);
  // The source without the switch still holds the header's text, but the
  // preprocessor drops it: nothing defines the switch ahead of it.
  EXPECT_EQ(without.find("#define MP_NODE_USES_THIN_FILM"), std::string::npos);
}

TEST(DeviceChoice, UnknownSelectorsAreRejected) {
  EXPECT_THROW(DeviceSession("banana"), Error);
  EXPECT_THROW(DeviceSession("99"), Error);
  ScopedEnv env("MICROPOLY_DEVICE", "cpu");
  DeviceSession cpu("");
  EXPECT_EQ(cpu.info().type, "cpu");
}

}  // namespace
}  // namespace mp

// Which devices get the tile sampler: PoCL on LLVM 14 or older aborts the
// process compiling it (PyPI's pocl-binary-distribution 3.0, which the
// extension carried before, reports LLVM 14.0.6); other platforms always get it.
TEST(TileSamplerGate, FollowsPoclsLlvm) {
  EXPECT_FALSE(mp::compiles_tile_sampler(
      "OpenCL 3.0 PoCL 3.0-rc2  Linux, Release, RELOC, LLVM 14.0.6, SLEEF, DISTRO, POCL_DEBUG"));
  EXPECT_TRUE(mp::compiles_tile_sampler(
      "OpenCL 3.0 PoCL 3.1+debian  Linux, None+Asserts, RELOC, SPIR, LLVM 15.0.6, SLEEF, DISTRO, POCL_DEBUG"));
  EXPECT_TRUE(mp::compiles_tile_sampler("OpenCL 3.0 CUDA 12.8.90"));
  EXPECT_TRUE(mp::compiles_tile_sampler("OpenCL 3.0 PoCL 6.0 Linux, Release, LLVM 18.1.8"));
}

// The gate reads the platform of the device a session runs on (the default
// one: the GPU where there is one): the tile sampler's kernels exist exactly
// where it says they compile.
TEST(TileSamplerGate, SessionProgramHoldsTheTileSamplerWhereAllowed) {
  mp::DeviceSession session("");
  const std::string version =
      cl::Platform(session.device().getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_VERSION>();
  EXPECT_EQ(session.tile_sampler(), mp::compiles_tile_sampler(version));
  bool found = true;
  try {
    cl::Kernel kernel(session.program(), "sample_tiles");
  } catch (const cl::Error&) {
    found = false;
  }
  EXPECT_EQ(found, session.tile_sampler()) << version;
}
