// Where a RIB file may read other files from: the untrusted-path policy for
// ReadArchive and texture names, and RenderMan's searchpath option.
//
// A scene file may come from anywhere, so the files it names are confined to
// the scene's own folder and the folders the user allows (RibReadOptions);
// names are compared after resolving "..", "." and symbolic links, so neither
// can lead out. The searchpath option only chooses where relative names are
// looked up; it never widens what may be read. See docs/rib.md, "Untrusted
// scene files".
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "rib/rib_reader.h"

namespace mp::rib {

// One folder of a search path; `requester` stands for RenderMan's default
// ('@'): the folder of the file that makes the request.
struct SearchEntry {
  bool requester = false;
  std::filesystem::path folder;  // absolute, when !requester
};
using SearchPath = std::vector<SearchEntry>;

// The default search path: the requesting file's folder only.
SearchPath default_search_path();

// Parses a searchpath value as RenderMan writes it: folders separated by ':',
// '@' for the default path and '&' for `previous`. Relative folders are taken
// relative to `base_dir` (the folder of the file holding the option). Empty
// entries are skipped.
SearchPath parse_search_path(const std::string& text, const SearchPath& previous, const std::string& base_dir);

// A file found for a request: `open` is the path to read (canonical when the
// file exists) and `shown` the name as found in its folder, for messages.
struct FoundFile {
  std::string open;
  std::string shown;
};

class PathPolicy {
 public:
  // `scene_dir` is the top-level scene file's folder (or read_rib_string's
  // base_dir). Folders that do not exist are kept as written.
  PathPolicy(const std::string& scene_dir, const RibReadOptions& options);

  // Finds the file a request names. Absolute names stand for themselves;
  // relative ones are tried in each folder of `search`, in order ('@' is
  // `requester_dir`), and the first that exists is taken; when none exists,
  // the first one is returned as written (opening it then reports that it is
  // missing). Throws RibError,
  // "WHERE: REQUEST ..." with the rule, when the file lies outside the allowed
  // folders and any path is not allowed.
  FoundFile find(const std::string& name, const SearchPath& search, const std::string& requester_dir,
                   const std::string& where, const std::string& request) const;
  // True when the user lifted the rule (RibReadOptions::allow_any_path).
  bool allows_any() const { return allow_any_; }

 private:
  bool allowed(const std::filesystem::path& canonical) const;
  std::vector<std::filesystem::path> roots_;  // canonical; roots_[0] is the scene's folder
  bool allow_any_ = false;
};

}  // namespace mp::rib
