// libFuzzer harness for the RIB reader (not built by default). Any input must
// either parse or throw mp::RibError; anything else (a crash, a sanitizer
// report, another exception) is a bug. Build and run from a scratch directory:
//   clang++ -std=c++17 -g -O1 -fsanitize=fuzzer,address,undefined \
//     -I native/include -I native/src tests/fuzz/rib_fuzz.cpp native/src/rib/*.cpp -o rib_fuzz
//   ./rib_fuzz -max_total_time=120 -max_len=4096 CORPUS_DIR tests/scenes
#include <cstddef>
#include <cstdint>
#include <string>

#include "rib/rib_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    mp::read_rib_string(std::string(reinterpret_cast<const char*>(data), size), "fuzz.rib", ".");
  } catch (const mp::RibError&) {
  }
  return 0;
}
