// Reading RIB files from disk (the top-level file and ReadArchive).
#pragma once

#include <string>

namespace mp::rib {

// Reads a regular file of at most `max_bytes`; on failure returns false and
// sets `error` to a short reason ("not found", "not a regular file", ...).
bool read_text_file(const std::string& path, size_t max_bytes, std::string* text, std::string* error);

// The directory holding `path` ("." when it has none), for relative archives.
std::string directory_of(const std::string& path);

}  // namespace mp::rib
