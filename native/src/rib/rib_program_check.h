// Material and world programs in a RIB file are OpenCL C source that the
// render device's compiler builds. Two things in such source reach beyond the
// device: preprocessor directives the compiler executes on the host (an
// #include of a file on disk, pragmas that drive the compiler itself) and
// inline assembly, which a CPU device (PoCL) runs as native code inside the
// rendering process. A program from a scene file may use neither.
#pragma once

#include <string>

namespace mp::rib {

// "" when `source` is acceptable, else the reason (one line, naming the
// construct). Accepted directives: define, undef, if, ifdef, ifndef, elif,
// else, endif, line, error, warning, "#pragma OPENCL ..." and "#pragma
// unroll", and an `#include "name"` line in the exact form the kernel
// assembler resolves from Micropoly's embedded headers (cl/program_cache.cpp),
// which never reaches the compiler. Token pasting (##) is refused too, since
// it could assemble a refused word.
std::string program_source_problem(const std::string& source);

}  // namespace mp::rib
