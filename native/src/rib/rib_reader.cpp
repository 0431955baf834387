// Public entry points of the RIB reader.
#include "rib/rib_reader.h"

#include <new>
#include <stdexcept>

#include "rib/rib_file.h"
#include "rib/rib_parser.h"

namespace mp {

RibResult read_rib_string(const std::string& text, const std::string& name,
                          const std::string& base_dir, const RibReadOptions& options) {
  try {
    rib::Parser parser(base_dir, options);
    parser.parse(text, name, base_dir, 0);
    return parser.finish(name);
  } catch (const RibError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw RibError(name + ":0: out of memory while reading the scene");
  } catch (const std::length_error&) {
    throw RibError(name + ":0: out of memory while reading the scene");
  }
}

RibResult read_rib_file(const std::string& path, const RibReadOptions& options) {
  std::string text, error;
  if (!rib::read_text_file(path, rib::Limits::kMaxFileBytes, &text, &error))
    throw RibError(path + ":0: cannot read the file: " + error);
  return read_rib_string(text, path, rib::directory_of(path), options);
}

}  // namespace mp
