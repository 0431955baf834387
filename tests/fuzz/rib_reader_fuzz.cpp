// RIB reader fuzz target. rib_reader.h promises that any bytes either parse
// into a Scene or throw mp::RibError (a malformed file) or mp::Error (a
// file it cannot read, such as a missing archive or texture). Anything else
// is a bug that libFuzzer reports: a crash or sanitizer report, another
// exception (which ends in std::terminate), or an input slower than -timeout.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "micropoly/error.h"
#include "rib/rib_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mp::fuzz::planted_bug(data, size);
  try {
    mp::read_rib_string(std::string(reinterpret_cast<const char*>(data), size), "fuzz.rib", ".");
  } catch (const mp::Error&) {  // mp::RibError included
  }
  return 0;
}
