// Reader for the RIB (RenderMan Interface Bytestream) subset Micropoly renders.
// It fills a Scene; see docs/rib.md for the requests it understands.
#pragma once

#include <string>
#include <vector>

#include "micropoly/error.h"
#include "micropoly/scene.h"

namespace mp {

// A malformed file: message is "FILE:LINE: reason".
class RibError : public Error {
 public:
  using Error::Error;
};

struct RibResult {
  Scene scene;
  std::string display_name;           // from Display, empty if none
  std::vector<std::string> warnings;  // one per unsupported request name
};

// Reads a RIB file (ReadArchive paths are relative to the including file).
// Throws RibError on malformed input; never crashes, whatever the bytes.
RibResult read_rib_file(const std::string& path);
// Same, from text in memory; `name` is used in messages and `base_dir` for ReadArchive.
RibResult read_rib_string(const std::string& text, const std::string& name,
                          const std::string& base_dir = ".");

}  // namespace mp
