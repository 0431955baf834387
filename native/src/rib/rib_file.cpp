#include "rib/rib_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

namespace mp::rib {

bool read_text_file(const std::string& path, size_t max_bytes, std::string* text, std::string* error) {
  // Only regular files: a device or FIFO (/dev/zero, a pipe) could never end.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    *error = std::strerror(errno);
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    *error = "not a regular file";
    return false;
  }
  if (static_cast<unsigned long long>(st.st_size) > max_bytes) {
    *error = "file larger than " + std::to_string(max_bytes >> 20) + " MiB";
    return false;
  }
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) {
    *error = std::strerror(errno);
    return false;
  }
  text->clear();
  text->reserve(static_cast<size_t>(st.st_size));
  char buf[1 << 16];
  for (;;) {
    const size_t n = std::fread(buf, 1, sizeof buf, f.get());
    if (n > 0) {
      if (text->size() + n > max_bytes) {
        *error = "file larger than " + std::to_string(max_bytes >> 20) + " MiB";
        return false;
      }
      text->append(buf, n);
    }
    if (n < sizeof buf) break;
  }
  if (std::ferror(f.get())) {
    *error = "read error";
    return false;
  }
  return true;
}

std::string directory_of(const std::string& path) {
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return dir.empty() ? "." : dir;
}

}  // namespace mp::rib
