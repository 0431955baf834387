#include "rib/rib_program_check.h"

#include <cctype>
#include <set>
#include <sstream>

namespace mp::rib {
namespace {

bool ident_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// Lines the kernel assembler replaces by an embedded header: optional spaces
// or tabs, then `#include "` (cl/program_cache.cpp, expand_includes). They are
// blanked here, since the compiler never sees them.
std::string without_embedded_includes(const std::string& source) {
  std::istringstream in(source);
  std::string line, out;
  while (std::getline(in, line)) {
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line.compare(first, 10, "#include \"") != 0) out += line;
    out += '\n';
  }
  return out;
}

// C translation phases 1 and 2 (C99 5.1.1.2) as far as they can form a
// directive: the trigraphs for '#' and '\', then backslash-newline splicing.
std::string spliced(const std::string& text) {
  std::string t;
  t.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '?' && i + 2 < text.size() && text[i + 1] == '?' && (text[i + 2] == '=' || text[i + 2] == '/')) {
      t += text[i + 2] == '=' ? '#' : '\\';
      i += 2;
    } else {
      t += text[i];
    }
  }
  std::string out;
  out.reserve(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    if (t[i] == '\\') {
      size_t j = i + 1;
      if (j < t.size() && t[j] == '\r') ++j;
      if (j < t.size() && t[j] == '\n') {
        i = j;
        continue;
      }
    }
    out += t[i];
  }
  return out;
}

}  // namespace

std::string program_source_problem(const std::string& source) {
  static const std::set<std::string> kDirectives = {"define", "undef", "if",   "ifdef", "ifndef",  "elif",
                                                    "else",   "endif", "line", "error", "warning", ""};
  const std::string s = spliced(without_embedded_includes(source));
  bool line_start = true;  // only blanks and comments since the last newline
  size_t i = 0;
  auto skip_blanks = [&](bool cross_lines) {
    for (;;) {
      if (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\f' || s[i] == '\v' || s[i] == '\r' ||
                           (cross_lines && s[i] == '\n'))) {
        ++i;
      } else if (s.compare(i, 2, "/*") == 0) {
        // A comment spanning lines still counts as blank for where a
        // directive may start (being strict here only refuses more).
        const size_t end = s.find("*/", i + 2);
        i = end == std::string::npos ? s.size() : end + 2;
      } else if (s.compare(i, 2, "//") == 0) {
        while (i < s.size() && s[i] != '\n') ++i;
      } else {
        return;
      }
    }
  };
  while (i < s.size()) {
    if (line_start) {
      skip_blanks(false);
      if (i >= s.size()) break;
      if (s[i] == '#' || s.compare(i, 2, "%:") == 0) {
        i += s[i] == '#' ? 1 : 2;
        skip_blanks(false);
        size_t end = i;
        while (end < s.size() && ident_char(s[end])) ++end;
        const std::string name = s.substr(i, end - i);
        i = end;
        if (name == "pragma") {
          skip_blanks(false);
          size_t e = i;
          while (e < s.size() && ident_char(s[e])) ++e;
          const std::string what = s.substr(i, e - i);
          if (what != "OPENCL" && what != "unroll") return "the directive #pragma " + what + " drives the compiler";
        } else if (!kDirectives.count(name)) {
          return "the directive #" + name + " is not accepted (the compiler would run it on the host)";
        }
      }
      line_start = false;
    }
    const char c = s[i];
    if (c == '\n') {
      line_start = true;
      ++i;
    } else if (c == '"' || c == '\'') {
      // A string or character literal: nothing inside forms a token.
      for (++i; i < s.size() && s[i] != c && s[i] != '\n'; ++i)
        if (s[i] == '\\') ++i;
      ++i;
    } else if (s.compare(i, 2, "/*") == 0 || s.compare(i, 2, "//") == 0) {
      skip_blanks(false);
    } else if (s.compare(i, 2, "##") == 0 || s.compare(i, 4, "%:%:") == 0) {
      // Token pasting could assemble the words refused below.
      return "token pasting (##) is not accepted";
    } else if (ident_char(c)) {
      size_t end = i;
      while (end < s.size() && ident_char(s[end])) ++end;
      const std::string word = s.substr(i, end - i);
      if (word == "asm" || word == "__asm" || word == "__asm__")
        return "inline assembly (" + word + ") would run as native code on a CPU device";
      if (word == "_Pragma" || word == "__pragma") return "the " + word + " operator drives the compiler";
      i = end;
    } else {
      ++i;
    }
  }
  return "";
}

}  // namespace mp::rib
