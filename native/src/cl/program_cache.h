// Builds the embedded kernel sources into a program, caching the device
// binary on disk per device, driver and source hash so a second run does not
// recompile. On PoCL, whose own kernel cache keeps the program and each
// kernel's code, the entry is only a record that this source was built (a
// binary would cost a compile of every kernel first; program_cache.cpp).
// Cache folder: $MICROPOLY_CACHE_DIR, else $XDG_CACHE_HOME/micropoly, else
// ~/.cache/micropoly. A cache that cannot be read or written is ignored.
#pragma once

#include <string>
#include <vector>

#include "cl/cl.h"

namespace mp {

// The complete program source: every kernels/*.cl with its #include "..."
// lines replaced by the embedded headers.
std::string assemble_program_source();

// One material program (kernels/materials/material_program.cl) with the
// add-on's generated node functions in place of its marker: a material's
// kernels, or (`world`) the world's.
std::string assemble_material_program_source(const std::string& generated, bool world = false);

// The "#define MP_NODE_USES_..." lines of a material program's generated
// code: switches it sets for the kernel headers.
std::vector<std::string> material_program_switches(const std::string& generated);

// The light program (kernels/materials/light_program.cl), with or without
// thin film (the one switch lighting reads).
std::string assemble_light_program_source(bool thin_film);

// The first error of an OpenCL compiler log as one line ("line L:C: error:
// ...", with a count of the others), for messages; the whole log is kept in
// the cache folder.
std::string first_build_error(const std::string& log);

struct BuiltProgram {
  cl::Program program;
  bool from_cache = false;  // a cached binary, or (PoCL) a source built here before
  double build_ms = 0;
};

BuiltProgram build_program_cached(const cl::Context& context, const cl::Device& device,
                                  const std::string& source, const std::string& options);

}  // namespace mp
