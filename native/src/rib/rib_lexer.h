// Tokenizer for the ASCII encoding of RIB (RenderMan Interface Bytestream,
// RI spec 3.2 appendix C). The binary encoding (bytes >= 0x80 outside strings
// and comments) and compressed files are rejected with a RibError, as is any
// control character or invalid UTF-8, so later stages only see clean tokens.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace mp::rib {

enum class TokenKind { End, Name, Number, String, ArrayBegin, ArrayEnd };

struct Token {
  TokenKind kind = TokenKind::End;
  int line = 0;
  double number = 0.0;  // TokenKind::Number: always finite and within float range
  std::string text;     // TokenKind::Name and TokenKind::String (escapes resolved)
};

// Length of the valid UTF-8 sequence starting at text[pos] (1 for ASCII), or 0
// if the bytes there are not valid UTF-8 (overlong forms, surrogates and code
// points above U+10FFFF are invalid). Shared with the writer, which must
// escape exactly the bytes the lexer would refuse.
size_t utf8_sequence_length(std::string_view text, size_t pos);

class Lexer {
 public:
  // `text` must outlive the lexer; `file` names it in error messages.
  Lexer(std::string_view text, std::string file);

  Token next();
  const std::string& file() const { return file_; }
  int line() const { return line_; }

  [[noreturn]] void fail(int line, const std::string& reason) const;

 private:
  void skip_space_and_comments();
  Token lex_string();
  Token lex_number();
  Token lex_name();
  size_t utf8_length(size_t pos) const { return utf8_sequence_length(text_, pos); }

  std::string_view text_;
  std::string file_;
  size_t pos_ = 0;
  int line_ = 1;
};

// Human-readable description of a token for error messages ("a number").
const char* describe(TokenKind kind);


}  // namespace mp::rib
