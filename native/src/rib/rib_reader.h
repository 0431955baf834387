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

// Which files a scene may read through ReadArchive and texture names. A
// scene file is untrusted input: by default it may read only files inside its
// own folder (after resolving "..", "." and symbolic links); see docs/rib.md,
// "Untrusted scene files".
struct RibReadOptions {
  // Further folders (and everything under them) the scene may read from.
  std::vector<std::string> allowed_roots;
  // Trusts the file: any readable file may be named, and material programs
  // are not checked for directives and inline assembly (rib_program_check.h).
  bool allow_any_path = false;
};

// Reads a RIB file (ReadArchive paths are relative to the including file).
// Throws RibError on malformed input, and on a file named outside the allowed
// folders; never crashes, whatever the bytes.
RibResult read_rib_file(const std::string& path, const RibReadOptions& options = {});
// Same, from text in memory; `name` is used in messages and `base_dir` for
// ReadArchive and textures (it is the scene's folder for the path rule).
RibResult read_rib_string(const std::string& text, const std::string& name,
                          const std::string& base_dir = ".", const RibReadOptions& options = {});

}  // namespace mp
