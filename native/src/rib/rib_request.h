// A RIB request is a name followed by values (numbers, strings, or arrays of
// either) up to the next name. Grouping tokens this way lets an unknown
// request be skipped without knowing its signature, and lets each handler see
// all of its arguments at once.
#pragma once

#include <string>
#include <vector>

#include "rib/rib_lexer.h"

namespace mp::rib {

struct Arg {
  enum class Kind { Number, String, NumberArray, StringArray, EmptyArray };
  Kind kind = Kind::Number;
  int line = 0;
  std::vector<double> numbers;       // Number (one value) and NumberArray
  std::vector<std::string> strings;  // String (one value) and StringArray

  bool is_array() const {
    return kind == Kind::NumberArray || kind == Kind::StringArray || kind == Kind::EmptyArray;
  }
  bool has_numbers() const {
    return kind == Kind::Number || kind == Kind::NumberArray || kind == Kind::EmptyArray;
  }
  bool has_strings() const {
    return kind == Kind::String || kind == Kind::StringArray || kind == Kind::EmptyArray;
  }
  size_t size() const { return has_strings() && kind != Kind::EmptyArray ? strings.size() : numbers.size(); }
  const char* describe() const;
};

struct Request {
  std::string name;
  int line = 0;
  std::vector<Arg> args;
};

// Reads requests from a lexer, one at a time.
class RequestReader {
 public:
  explicit RequestReader(Lexer& lexer);
  // Fills `out` with the next request; false at the end of the text.
  bool next(Request& out);
  Lexer& lexer() { return lexer_; }

 private:
  void read_array(Arg& arg, int start_line);

  Lexer& lexer_;
  Token look_;
};

// Positional access to a request's arguments, with errors that name the
// request and the line. Values that must be integers are checked to be
// integral and in range, so no float-to-int conversion is ever undefined.
class ArgReader {
 public:
  ArgReader(const Request& req, const std::string& file);

  const Request& request() const { return req_; }
  size_t position() const { return next_; }
  size_t remaining() const { return req_.args.size() - next_; }
  bool at_end() const { return next_ >= req_.args.size(); }
  const Arg& peek() const;

  double number();
  int integer(long long lo, long long hi);
  std::string string();
  // `n` numbers given either as n scalars or as one array of n values.
  std::vector<double> numbers(size_t n);
  const Arg& number_array();  // an array of numbers (possibly empty)
  const Arg& string_array();  // an array of strings (possibly empty)
  const Arg& any();           // the next argument, whatever it is
  // Integers from an array of numbers, each in [lo, hi].
  std::vector<int> int_array(const Arg& arg, long long lo, long long hi, const char* what);
  // Errors if arguments are left over (for requests without parameter lists).
  void done();

  [[noreturn]] void fail(const std::string& reason) const;
  [[noreturn]] void fail_at(int line, const std::string& reason) const;
  const std::string& file() const { return file_; }

 private:
  const Arg& take(const char* expected);

  const Request& req_;
  const std::string& file_;
  size_t next_ = 0;
};

// Converts a finite double to int if it is integral and within [lo, hi].
bool to_int(double v, long long lo, long long hi, int* out);

}  // namespace mp::rib
