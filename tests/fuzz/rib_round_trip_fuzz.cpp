// RIB round-trip fuzz target: whatever the reader accepts and the writer
// writes (rib_writer.h: any valid Scene) must read back as the same Scene,
// field by field (scene_compare.h). A difference, or a written file that no
// longer reads, traps so that libFuzzer saves the input; the difference is
// printed first.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <system_error>
#include <unistd.h>

#include "fuzz_support.h"
#include "micropoly/error.h"
#include "rib/rib_reader.h"
#include "rib/rib_writer.h"
#include "scene_compare.h"

namespace {

// Texture images of the written scene go to a folder of this process
// (rewritten by every input that has images).
const std::string& image_folder() {
  static const std::string folder = [] {
    const std::filesystem::path p =
        std::filesystem::temp_directory_path() / ("micropoly-fuzz-textures-" + std::to_string(getpid()));
    std::filesystem::create_directories(p);
    return p.string();
  }();
  return folder;
}

[[noreturn]] void report(const char* what, const std::string& detail, const std::string& written) {
  std::fprintf(stderr, "RIB round trip: %s: %s\n--- written RIB ---\n%s\n--- end ---\n", what, detail.c_str(),
               written.c_str());
  __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mp::fuzz::planted_bug(data, size);
  mp::RibResult first;
  try {
    first = mp::read_rib_string(std::string(reinterpret_cast<const char*>(data), size), "fuzz.rib", ".");
  } catch (const mp::Error&) {
    return 0;  // not a scene: the reader target covers how it fails
  }
  std::ostringstream out;
  try {
    mp::write_rib(first.scene, out, first.display_name, image_folder());
  } catch (const mp::Error&) {
    return 0;  // read, but not a valid Scene: the writer validates and refuses it
  }
  const std::string written = out.str();
  mp::RibResult second;
  try {
    second = mp::read_rib_string(written, "written.rib", ".");
  } catch (const mp::Error& e) {
    report("the written RIB does not read back", e.what(), written);
  }
  if (second.display_name != first.display_name)
    report("display name", first.display_name + " vs " + second.display_name, written);
  const std::string diff = mp::fuzz::first_difference(first.scene, second.scene);
  if (!diff.empty()) report("the scene read back differs", diff, written);
  return 0;
}
