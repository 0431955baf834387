#include "rib/rib_request.h"

#include <cctype>
#include <cmath>

#include "rib/rib_reader.h"

namespace mp::rib {
namespace {

std::string quoted_prefix(const std::string& s) {
  return "\"" + (s.size() > 40 ? s.substr(0, 40) + "..." : s) + "\"";
}

}  // namespace

const char* Arg::describe() const {
  switch (kind) {
    case Kind::Number: return "a number";
    case Kind::String: return "a string";
    case Kind::NumberArray: return "an array of numbers";
    case Kind::StringArray: return "an array of strings";
    case Kind::EmptyArray: return "an empty array";
  }
  return "a value";
}

bool to_int(double v, long long lo, long long hi, int* out) {
  if (!std::isfinite(v) || v != std::floor(v)) return false;
  if (v < static_cast<double>(lo) || v > static_cast<double>(hi)) return false;
  *out = static_cast<int>(v);
  return true;
}

// --- RequestReader ------------------------------------------------------------

RequestReader::RequestReader(Lexer& lexer) : lexer_(lexer) { look_ = lexer_.next(); }

bool RequestReader::next(Request& out) {
  if (look_.kind == TokenKind::End) return false;
  if (look_.kind != TokenKind::Name) {
    std::string what = describe(look_.kind);
    if (look_.kind == TokenKind::String) what += " " + quoted_prefix(look_.text);
    lexer_.fail(look_.line, "expected a request name, found " + what);
  }
  out.name = std::move(look_.text);
  out.line = look_.line;
  out.args.clear();
  for (;;) {
    look_ = lexer_.next();
    switch (look_.kind) {
      case TokenKind::Number: {
        Arg a;
        a.kind = Arg::Kind::Number;
        a.line = look_.line;
        a.numbers.push_back(look_.number);
        out.args.push_back(std::move(a));
        break;
      }
      case TokenKind::String: {
        Arg a;
        a.kind = Arg::Kind::String;
        a.line = look_.line;
        a.strings.push_back(std::move(look_.text));
        out.args.push_back(std::move(a));
        break;
      }
      case TokenKind::ArrayBegin: {
        Arg a;
        a.kind = Arg::Kind::EmptyArray;
        a.line = look_.line;
        read_array(a, look_.line);
        out.args.push_back(std::move(a));
        break;
      }
      case TokenKind::ArrayEnd:
        lexer_.fail(look_.line, "']' without a matching '['");
      case TokenKind::Name:
      case TokenKind::End:
        return true;
    }
  }
}

void RequestReader::read_array(Arg& arg, int start_line) {
  for (;;) {
    Token tok = lexer_.next();
    switch (tok.kind) {
      case TokenKind::Number:
        if (arg.kind == Arg::Kind::StringArray)
          lexer_.fail(tok.line, "array mixes strings and numbers");
        arg.kind = Arg::Kind::NumberArray;
        arg.numbers.push_back(tok.number);
        break;
      case TokenKind::String:
        if (arg.kind == Arg::Kind::NumberArray)
          lexer_.fail(tok.line, "array mixes numbers and strings");
        arg.kind = Arg::Kind::StringArray;
        arg.strings.push_back(std::move(tok.text));
        break;
      case TokenKind::ArrayEnd:
        return;
      case TokenKind::ArrayBegin:
        lexer_.fail(tok.line, "nested arrays are not allowed");
      case TokenKind::Name: {
        // RIB has no literal for a non-number: a NaN or an infinity written
        // out by some exporter lexes as a name, which is not a request.
        std::string lower = tok.text;
        for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        for (const char* bad : {"nan", "-nan", "+nan", "inf", "-inf", "+inf", "infinity", "-infinity"})
          if (lower == bad) lexer_.fail(tok.line, "'" + tok.text + "' in an array is not a finite number");
        lexer_.fail(start_line, "unterminated array: '[' is not closed before request '" +
                                    tok.text + "' at line " + std::to_string(tok.line));
      }
      case TokenKind::End:
        lexer_.fail(start_line, "unterminated array: '[' is not closed before the end of the file");
    }
  }
}

// --- ArgReader ----------------------------------------------------------------

ArgReader::ArgReader(const Request& req, const std::string& file) : req_(req), file_(file) {}

void ArgReader::fail(const std::string& reason) const { fail_at(req_.line, reason); }

void ArgReader::fail_at(int line, const std::string& reason) const {
  throw RibError(file_ + ":" + std::to_string(line) + ": " + req_.name + ": " + reason);
}

const Arg& ArgReader::peek() const {
  if (at_end()) fail("missing arguments");
  return req_.args[next_];
}

const Arg& ArgReader::take(const char* expected) {
  if (at_end())
    fail(std::string("missing argument ") + std::to_string(next_ + 1) + " (" + expected + ")");
  return req_.args[next_++];
}

const Arg& ArgReader::any() { return take("a value"); }

double ArgReader::number() {
  const Arg& a = take("a number");
  // A one-element array is accepted where a number is expected ("fov" [45]).
  if ((a.kind == Arg::Kind::Number || a.kind == Arg::Kind::NumberArray) && a.numbers.size() == 1)
    return a.numbers[0];
  fail_at(a.line, "argument " + std::to_string(next_) + ": expected a number, found " + a.describe());
}

int ArgReader::integer(long long lo, long long hi) {
  const int line = at_end() ? req_.line : req_.args[next_].line;
  const double v = number();
  int out = 0;
  if (!to_int(v, lo, hi, &out))
    fail_at(line, "argument " + std::to_string(next_) + ": expected an integer in [" +
                      std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return out;
}

std::string ArgReader::string() {
  const Arg& a = take("a string");
  if ((a.kind == Arg::Kind::String || a.kind == Arg::Kind::StringArray) && a.strings.size() == 1)
    return a.strings[0];
  fail_at(a.line, "argument " + std::to_string(next_) + ": expected a string, found " + a.describe());
}

std::vector<double> ArgReader::numbers(size_t n) {
  if (!at_end() && req_.args[next_].is_array()) {
    const Arg& a = take("an array");
    if (!a.has_numbers() || a.numbers.size() != n)
      fail_at(a.line, "expected an array of " + std::to_string(n) + " numbers, found " +
                          a.describe() + " of " + std::to_string(a.size()));
    return a.numbers;
  }
  std::vector<double> out;
  out.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const Arg& a = take("a number");
    if (a.kind != Arg::Kind::Number)
      fail_at(a.line, "argument " + std::to_string(next_) + ": expected a number, found " + a.describe());
    out.push_back(a.numbers[0]);
  }
  return out;
}

const Arg& ArgReader::number_array() {
  const Arg& a = take("an array of numbers");
  if (a.kind != Arg::Kind::NumberArray && a.kind != Arg::Kind::EmptyArray)
    fail_at(a.line, "argument " + std::to_string(next_) + ": expected an array of numbers, found " +
                        a.describe());
  return a;
}

const Arg& ArgReader::string_array() {
  const Arg& a = take("an array of strings");
  if (a.kind != Arg::Kind::StringArray && a.kind != Arg::Kind::EmptyArray)
    fail_at(a.line, "argument " + std::to_string(next_) + ": expected an array of strings, found " +
                        a.describe());
  return a;
}

std::vector<int> ArgReader::int_array(const Arg& arg, long long lo, long long hi, const char* what) {
  std::vector<int> out;
  out.reserve(arg.numbers.size());
  for (size_t i = 0; i < arg.numbers.size(); ++i) {
    int v = 0;
    if (!to_int(arg.numbers[i], lo, hi, &v))
      fail_at(arg.line, std::string(what) + "[" + std::to_string(i) + "] = " +
                            std::to_string(arg.numbers[i]) + " is not an integer in [" +
                            std::to_string(lo) + ", " + std::to_string(hi) + "]");
    out.push_back(v);
  }
  return out;
}

void ArgReader::done() {
  if (!at_end())
    fail_at(req_.args[next_].line, "too many arguments (" + std::to_string(req_.args.size()) +
                                       ", expected " + std::to_string(next_) + ")");
}

}  // namespace mp::rib
