#include "rib/rib_paths.h"

#include <system_error>

namespace mp::rib {
namespace fs = std::filesystem;
namespace {

// The absolute form of `p` with "..", "." and every symbolic link of its
// existing part resolved (std::filesystem::weakly_canonical); a part that does
// not exist yet is only normalised lexically.
fs::path canonical_form(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) abs = p;
  fs::path c = fs::weakly_canonical(abs, ec);
  return ec ? abs.lexically_normal() : c;
}

// True when every component of `root` starts `path` (both canonical), so
// "/a/bc" is not inside "/a/b".
bool is_within(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

bool file_exists(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec) && !ec;
}

}  // namespace

SearchPath default_search_path() { return {SearchEntry{true, {}}}; }

SearchPath parse_search_path(const std::string& text, const SearchPath& previous, const std::string& base_dir) {
  SearchPath out;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(':', start);
    if (end == std::string::npos) end = text.size();
    const std::string entry = text.substr(start, end - start);
    start = end + 1;
    if (entry.empty()) continue;
    if (entry == "@") {
      out.push_back(SearchEntry{true, {}});
    } else if (entry == "&") {
      out.insert(out.end(), previous.begin(), previous.end());
    } else {
      fs::path folder(entry);
      if (folder.is_relative()) folder = fs::path(base_dir.empty() ? "." : base_dir) / folder;
      std::error_code ec;
      const fs::path abs = fs::absolute(folder, ec);
      out.push_back(SearchEntry{false, ec ? folder : abs});
    }
  }
  return out;
}

PathPolicy::PathPolicy(const std::string& scene_dir, const RibReadOptions& options)
    : allow_any_(options.allow_any_path) {
  roots_.push_back(canonical_form(scene_dir.empty() ? "." : scene_dir));
  for (const std::string& r : options.allowed_roots)
    if (!r.empty()) roots_.push_back(canonical_form(r));
}

bool PathPolicy::allowed(const fs::path& canonical) const {
  if (allow_any_) return true;
  for (const fs::path& root : roots_)
    if (is_within(canonical, root)) return true;
  return false;
}

FoundFile PathPolicy::find(const std::string& name, const SearchPath& search, const std::string& requester_dir,
                             const std::string& where, const std::string& request) const {
  std::vector<fs::path> candidates;
  const fs::path named(name);
  if (named.is_absolute() || name.empty()) {
    candidates.push_back(named);
  } else {
    for (const SearchEntry& e : search)
      candidates.push_back((e.requester ? fs::path(requester_dir.empty() ? "." : requester_dir) : e.folder) / named);
    if (candidates.empty()) candidates.push_back(fs::path(requester_dir.empty() ? "." : requester_dir) / named);
  }
  // The first candidate that exists is the file; with none, the first one is
  // checked too, so that a missing file outside the allowed folders is
  // refused rather than reported missing.
  const fs::path* chosen = &candidates.front();
  for (const fs::path& c : candidates)
    if (file_exists(c)) {
      chosen = &c;
      break;
    }
  const fs::path canonical = canonical_form(*chosen);
  if (!allowed(canonical))
    throw RibError(where + ": " + request + " \"" + name + "\" refused: " + canonical.string() +
                   " is outside the scene's folder " + roots_.front().string() +
                   " and the allowed folders (allow it with --allow-path DIR or --allow-any-path)");
  return FoundFile{file_exists(*chosen) ? canonical.string() : chosen->string(), chosen->string()};
}

}  // namespace mp::rib
