// Parameter lists: "token" value pairs after a request's positional arguments.
// A token is either a declared name ("P", "Ka", or one from Declare) or an
// inline declaration ("uniform float Ka", "vertex point P", "float[2] st").
// Declarations give the class and type so values can be checked (RI spec 3.2,
// section 4 "Declare" and the table of standard variables).
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "rib/rib_request.h"

namespace mp::rib {

enum class VarClass { Constant, Uniform, Varying, Vertex, FaceVarying, FaceVertex };
enum class VarType { Float, Integer, Point, Vector, Normal, Color, String, Matrix, HPoint };

struct Declaration {
  VarClass cls = VarClass::Uniform;
  VarType type = VarType::Float;
  int array_size = 1;  // "float[2]" -> 2
  // Values per element: 3 for point/color, 4 for hpoint, 16 for matrix, ...
  int components() const;
  bool is_string() const { return type == VarType::String; }
};

// Parses "[class] type['['n']']" (as given to Declare); `name` is empty.
// With `with_name`, parses the inline form "[class] type['['n']'] name".
// Returns false if malformed.
bool parse_declaration(const std::string& text, bool with_name, Declaration* decl, std::string* name);

// Global declarations: the RI standard variables plus those made by Declare.
class DeclarationTable {
 public:
  DeclarationTable();
  void declare(const std::string& name, const Declaration& decl) { table_[name] = decl; }
  const Declaration* find(const std::string& name) const;

 private:
  std::unordered_map<std::string, Declaration> table_;
};

struct Param {
  std::string name;      // without the inline declaration
  Declaration decl;      // declared or inferred from the values
  bool declared = false; // false: type inferred (undeclared name)
  const Arg* value = nullptr;
  int line = 0;
};

class ParamList {
 public:
  // Reads the remaining arguments of `args` as token/value pairs, checking
  // each value against its declaration (strings vs numbers, element size).
  ParamList(ArgReader& args, const DeclarationTable& decls);

  const std::vector<Param>& params() const { return params_; }
  const Param* find(const std::string& name) const;

  // Typed access for uniform/constant values (shader and option parameters):
  // the value must hold exactly `n` numbers (or one string). Absent -> default.
  float get_float(const std::string& name, float fallback) const;
  void get_floats(const std::string& name, float* out, size_t n) const;  // unchanged if absent
  // Any number of numbers, each finite (an error otherwise); empty if absent.
  std::vector<float> get_float_list(const std::string& name) const;
  std::string get_string(const std::string& name, const std::string& fallback) const;
  // One integer in [lo, hi] (an error at the parameter's line otherwise);
  // `out` is unchanged when the parameter is absent.
  void get_int(const std::string& name, long long lo, long long hi, int* out) const;
  // One number for which `valid` holds; otherwise an error at the
  // parameter's line: parameter "name" must be `must_be`.
  float get_float_checked(const std::string& name, float fallback, bool (*valid)(float),
                          const std::string& must_be) const;

 private:
  ArgReader& args_;
  std::vector<Param> params_;
};

}  // namespace mp::rib
