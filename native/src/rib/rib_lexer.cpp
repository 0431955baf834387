#include "rib/rib_lexer.h"

#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "rib/rib_reader.h"

namespace mp::rib {
namespace {

bool is_digit(unsigned char c) { return c >= '0' && c <= '9'; }
bool is_letter(unsigned char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool is_name_char(unsigned char c) { return is_letter(c) || is_digit(c) || c == '_'; }

std::string hex_byte(unsigned char c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(c));
  return buf;
}

}  // namespace

const char* describe(TokenKind kind) {
  switch (kind) {
    case TokenKind::End: return "the end of the file";
    case TokenKind::Name: return "a request name";
    case TokenKind::Number: return "a number";
    case TokenKind::String: return "a string";
    case TokenKind::ArrayBegin: return "'['";
    case TokenKind::ArrayEnd: return "']'";
  }
  return "a token";
}

Lexer::Lexer(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

void Lexer::fail(int line, const std::string& reason) const {
  throw RibError(file_ + ":" + std::to_string(line) + ": " + reason);
}

size_t utf8_sequence_length(std::string_view text, size_t pos) {
  auto byte = [&](size_t i) -> int {
    return i < text.size() ? static_cast<unsigned char>(text[i]) : -1;
  };
  auto cont = [&](size_t i, int lo = 0x80, int hi = 0xBF) {
    int b = byte(i);
    return b >= lo && b <= hi;
  };
  const int b0 = byte(pos);
  if (b0 < 0x80) return b0 < 0 ? 0 : 1;
  if (b0 >= 0xC2 && b0 <= 0xDF) return cont(pos + 1) ? 2 : 0;
  if (b0 >= 0xE0 && b0 <= 0xEF) {
    // Exclude overlong forms (E0 80..9F) and UTF-16 surrogates (ED A0..BF).
    const int lo = b0 == 0xE0 ? 0xA0 : 0x80;
    const int hi = b0 == 0xED ? 0x9F : 0xBF;
    return cont(pos + 1, lo, hi) && cont(pos + 2) ? 3 : 0;
  }
  if (b0 >= 0xF0 && b0 <= 0xF4) {
    // Exclude overlong forms (F0 80..8F) and code points above U+10FFFF.
    const int lo = b0 == 0xF0 ? 0x90 : 0x80;
    const int hi = b0 == 0xF4 ? 0x8F : 0xBF;
    return cont(pos + 1, lo, hi) && cont(pos + 2) && cont(pos + 3) ? 4 : 0;
  }
  return 0;
}

void Lexer::skip_space_and_comments() {
  while (pos_ < text_.size()) {
    const unsigned char c = static_cast<unsigned char>(text_[pos_]);
    if (c == '\n') {
      ++line_;
      ++pos_;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++pos_;
    } else if (c == '#') {
      // Comments (including "##" structure comments) run to the end of the line.
      while (pos_ < text_.size() && text_[pos_] != '\n') {
        const unsigned char d = static_cast<unsigned char>(text_[pos_]);
        if (d >= 0x80) {
          const size_t n = utf8_length(pos_);
          if (n == 0) fail(line_, "invalid UTF-8 in a comment");
          pos_ += n;
          continue;
        }
        if ((d < 0x20 && d != '\t' && d != '\r') || d == 0x7F)
          fail(line_, "control character " + hex_byte(d) + " in a comment");
        ++pos_;
      }
    } else {
      return;
    }
  }
}

Token Lexer::next() {
  skip_space_and_comments();
  Token tok;
  tok.line = line_;
  if (pos_ >= text_.size()) return tok;
  const unsigned char c = static_cast<unsigned char>(text_[pos_]);
  if (c == '"') return lex_string();
  if (c == '[' || c == ']') {
    ++pos_;
    tok.kind = c == '[' ? TokenKind::ArrayBegin : TokenKind::ArrayEnd;
    return tok;
  }
  if (is_digit(c) || c == '-' || c == '+' || c == '.') return lex_number();
  if (is_letter(c)) return lex_name();
  if (pos_ == 0 && c == 0x1F && text_.size() > 1 && static_cast<unsigned char>(text_[1]) == 0x8B)
    fail(line_, "compressed (gzip) RIB is not supported; decompress the file first");
  if (c >= 0x80)
    fail(line_, "byte " + hex_byte(c) + ": binary-encoded RIB is not supported (ASCII RIB only)");
  if (c < 0x20 || c == 0x7F) fail(line_, "unexpected control character " + hex_byte(c));
  fail(line_, std::string("unexpected character '") + static_cast<char>(c) + "'");
}

Token Lexer::lex_name() {
  Token tok;
  tok.kind = TokenKind::Name;
  tok.line = line_;
  const size_t start = pos_;
  while (pos_ < text_.size() && is_name_char(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  tok.text.assign(text_.substr(start, pos_ - start));
  return tok;
}

Token Lexer::lex_number() {
  Token tok;
  tok.kind = TokenKind::Number;
  tok.line = line_;
  const size_t start = pos_;
  auto at = [&](size_t i) -> unsigned char {
    return i < text_.size() ? static_cast<unsigned char>(text_[i]) : 0;
  };
  size_t p = pos_;
  if (at(p) == '+' || at(p) == '-') ++p;
  size_t digits = 0;
  while (is_digit(at(p))) ++p, ++digits;
  if (at(p) == '.') {
    ++p;
    while (is_digit(at(p))) ++p, ++digits;
  }
  bool ok = digits > 0;
  if (ok && (at(p) == 'e' || at(p) == 'E')) {
    ++p;
    if (at(p) == '+' || at(p) == '-') ++p;
    size_t exp_digits = 0;
    while (is_digit(at(p))) ++p, ++exp_digits;
    ok = exp_digits > 0;
  }
  // A number must end at a delimiter: "1.5.2", "3x" or "--1" are errors.
  const unsigned char after = at(p);
  if (is_name_char(after) || after == '.' || after == '+' || after == '-') ok = false;
  if (!ok) {
    size_t end = p;
    while (end < text_.size() && end - start < 32 &&
           (is_name_char(at(end)) || at(end) == '.' || at(end) == '+' || at(end) == '-'))
      ++end;
    fail(line_, "malformed number '" + std::string(text_.substr(start, end - start)) + "'");
  }
  const char* first = text_.data() + start;
  if (*first == '+') ++first;  // from_chars does not accept a leading '+'
  double value = 0.0;
  const auto res = std::from_chars(first, text_.data() + p, value);
  // Out of range: what rounds to infinity as a float, from FLT_MAX plus half
  // its ulp (2^104) on; the shortest decimal of FLT_MAX, 3.4028235e38, lies
  // just above FLT_MAX and must still read.
  if (res.ec != std::errc() || res.ptr != text_.data() + p || !std::isfinite(value) ||
      std::fabs(value) >= static_cast<double>(FLT_MAX) + 0x1p103)
    fail(line_, "number '" + std::string(text_.substr(start, p - start)) + "' is out of range");
  tok.number = value;
  pos_ = p;
  return tok;
}

Token Lexer::lex_string() {
  Token tok;
  tok.kind = TokenKind::String;
  tok.line = line_;
  const int start_line = line_;
  ++pos_;  // opening quote
  for (;;) {
    if (pos_ >= text_.size()) fail(start_line, "unterminated string");
    const unsigned char c = static_cast<unsigned char>(text_[pos_]);
    if (c == '"') {
      ++pos_;
      return tok;
    }
    if (c == '\\') {
      ++pos_;
      if (pos_ >= text_.size()) fail(start_line, "unterminated string");
      const unsigned char e = static_cast<unsigned char>(text_[pos_]);
      if (e >= '0' && e <= '7') {
        // Octal escape \ddd (C conventions, as in the RI spec's RIB strings).
        unsigned value = 0;
        for (int k = 0; k < 3 && pos_ < text_.size() && text_[pos_] >= '0' && text_[pos_] <= '7';
             ++k, ++pos_)
          value = value * 8 + static_cast<unsigned>(text_[pos_] - '0');
        if (value == 0 || value > 0xFF) fail(line_, "invalid octal escape in a string");
        tok.text.push_back(static_cast<char>(value));
        continue;
      }
      ++pos_;
      switch (e) {
        case 'n': tok.text.push_back('\n'); break;
        case 't': tok.text.push_back('\t'); break;
        case 'r': tok.text.push_back('\r'); break;
        case 'b': tok.text.push_back('\b'); break;
        case 'f': tok.text.push_back('\f'); break;
        case '\n': ++line_; break;  // backslash-newline continues the string
        default:
          if (e < 0x20 || e >= 0x7F) fail(line_, "invalid escape in a string");
          tok.text.push_back(static_cast<char>(e));  // \\, \", and any other literal
      }
      continue;
    }
    if (c == '\n') {
      ++line_;
      tok.text.push_back('\n');
      ++pos_;
      continue;
    }
    if (c >= 0x80) {
      const size_t n = utf8_length(pos_);
      if (n == 0) fail(line_, "invalid UTF-8 in a string");
      tok.text.append(text_.substr(pos_, n));
      pos_ += n;
      continue;
    }
    if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7F)
      fail(line_, "control character " + hex_byte(c) + " in a string");
    tok.text.push_back(static_cast<char>(c));
    ++pos_;
  }
}

}  // namespace mp::rib
