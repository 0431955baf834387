#include "rib/rib_params.h"

#include <cmath>
#include <sstream>

namespace mp::rib {
namespace {

bool parse_class(const std::string& w, VarClass* out) {
  static const std::pair<const char*, VarClass> kClasses[] = {
      {"constant", VarClass::Constant},       {"uniform", VarClass::Uniform},
      {"varying", VarClass::Varying},         {"vertex", VarClass::Vertex},
      {"facevarying", VarClass::FaceVarying}, {"facevertex", VarClass::FaceVertex}};
  for (const auto& [name, cls] : kClasses)
    if (w == name) return *out = cls, true;
  return false;
}

bool parse_type(const std::string& w, VarType* out) {
  static const std::pair<const char*, VarType> kTypes[] = {
      {"float", VarType::Float},   {"integer", VarType::Integer}, {"int", VarType::Integer},
      {"point", VarType::Point},   {"vector", VarType::Vector},   {"normal", VarType::Normal},
      {"color", VarType::Color},   {"string", VarType::String},   {"matrix", VarType::Matrix},
      {"hpoint", VarType::HPoint}};
  for (const auto& [name, type] : kTypes)
    if (w == name) return *out = type, true;
  return false;
}

Declaration decl(VarClass cls, VarType type, int n = 1) {
  Declaration d;
  d.cls = cls;
  d.type = type;
  d.array_size = n;
  return d;
}

}  // namespace

int Declaration::components() const {
  int per = 1;
  switch (type) {
    case VarType::Float:
    case VarType::Integer:
    case VarType::String: per = 1; break;
    case VarType::Point:
    case VarType::Vector:
    case VarType::Normal:
    case VarType::Color: per = 3; break;  // ColorSamples is fixed at 3
    case VarType::HPoint: per = 4; break;
    case VarType::Matrix: per = 16; break;
  }
  return per * array_size;
}

bool parse_declaration(const std::string& text, bool with_name, Declaration* out, std::string* name) {
  // Split on whitespace with '[' and ']' as separate words: "float[2] st".
  std::string spaced;
  for (char c : text) {
    if (c == '[' || c == ']') {
      spaced += ' ';
      spaced += c;
      spaced += ' ';
    } else {
      spaced += c;
    }
  }
  std::istringstream in(spaced);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  size_t i = 0;
  Declaration d;
  if (i < words.size() && parse_class(words[i], &d.cls)) ++i;
  if (i >= words.size() || !parse_type(words[i], &d.type)) return false;
  ++i;
  if (i < words.size() && words[i] == "[") {
    if (i + 2 >= words.size() || words[i + 2] != "]") return false;
    const std::string& n = words[i + 1];
    if (n.empty() || n.size() > 6 || n.find_first_not_of("0123456789") != std::string::npos)
      return false;
    d.array_size = std::stoi(n);
    if (d.array_size < 1) return false;
    i += 3;
  }
  if (with_name) {
    if (i + 1 != words.size()) return false;
    *name = words[i];
  } else if (i != words.size()) {
    return false;
  }
  *out = d;
  return true;
}

DeclarationTable::DeclarationTable() {
  // Standard primitive variables (RI spec 3.2, table 5.1).
  declare("P", decl(VarClass::Vertex, VarType::Point));
  declare("Pz", decl(VarClass::Vertex, VarType::Float));
  declare("Pw", decl(VarClass::Vertex, VarType::HPoint));
  declare("N", decl(VarClass::Varying, VarType::Normal));
  declare("Np", decl(VarClass::Uniform, VarType::Normal));
  declare("Cs", decl(VarClass::Varying, VarType::Color));
  declare("Os", decl(VarClass::Varying, VarType::Color));
  declare("s", decl(VarClass::Varying, VarType::Float));
  declare("t", decl(VarClass::Varying, VarType::Float));
  declare("st", decl(VarClass::Varying, VarType::Float, 2));
  // Parameters of the standard shaders and requests this reader understands.
  for (const char* f : {"Ka", "Kd", "Ks", "roughness", "intensity", "coneangle", "conedeltaangle",
                        "beamdistribution", "fov"})
    declare(f, decl(VarClass::Uniform, VarType::Float));
  declare("specularcolor", decl(VarClass::Uniform, VarType::Color));
  declare("lightcolor", decl(VarClass::Uniform, VarType::Color));
  declare("shadowname", decl(VarClass::Uniform, VarType::String));
  declare("from", decl(VarClass::Uniform, VarType::Point));
  declare("to", decl(VarClass::Uniform, VarType::Point));
}

const Declaration* DeclarationTable::find(const std::string& name) const {
  auto it = table_.find(name);
  return it == table_.end() ? nullptr : &it->second;
}

ParamList::ParamList(ArgReader& args, const DeclarationTable& decls) : args_(args) {
  while (!args.at_end()) {
    const Arg& token = args.any();
    if (token.kind != Arg::Kind::String)
      args.fail_at(token.line, "expected a parameter name (a string), found " +
                                   std::string(token.describe()));
    if (args.at_end())
      args.fail_at(token.line, "parameter \"" + token.strings[0] + "\" has no value");
    Param p;
    p.line = token.line;
    p.value = &args.any();
    const std::string& text = token.strings[0];
    if (text.find_first_of(" \t\n[") != std::string::npos) {
      if (!parse_declaration(text, true, &p.decl, &p.name))
        args.fail_at(token.line, "malformed inline declaration \"" + text + "\"");
      p.declared = true;
    } else if (const Declaration* d = decls.find(text)) {
      p.name = text;
      p.decl = *d;
      p.declared = true;
    } else {
      // Undeclared: infer the type from the values so the list can be skipped.
      p.name = text;
      p.decl.type = p.value->has_strings() && p.value->kind != Arg::Kind::EmptyArray
                        ? VarType::String
                        : VarType::Float;
    }
    const Arg& v = *p.value;
    if (p.decl.is_string() ? !v.has_strings() : !v.has_numbers())
      args.fail_at(v.line, "parameter \"" + p.name + "\" expects " +
                               (p.decl.is_string() ? "strings" : "numbers") + ", found " +
                               v.describe());
    const size_t per = static_cast<size_t>(p.decl.components());
    if (v.size() % per != 0)
      args.fail_at(v.line, "parameter \"" + p.name + "\" needs a multiple of " +
                               std::to_string(per) + " values, found " + std::to_string(v.size()));
    params_.push_back(std::move(p));
  }
}

const Param* ParamList::find(const std::string& name) const {
  for (auto it = params_.rbegin(); it != params_.rend(); ++it)
    if (it->name == name) return &*it;
  return nullptr;
}

float ParamList::get_float(const std::string& name, float fallback) const {
  float v = fallback;
  get_floats(name, &v, 1);
  return v;
}

void ParamList::get_floats(const std::string& name, float* out, size_t n) const {
  const Param* p = find(name);
  if (!p) return;
  if (p->decl.is_string() || p->value->numbers.size() != n)
    args_.fail_at(p->line, "parameter \"" + name + "\" expects " + std::to_string(n) +
                               (n == 1 ? " number" : " numbers") + ", found " +
                               std::to_string(p->value->size()) + " values");
  for (size_t i = 0; i < n; ++i) out[i] = static_cast<float>(p->value->numbers[i]);
}

std::vector<float> ParamList::get_float_list(const std::string& name) const {
  std::vector<float> out;
  const Param* p = find(name);
  if (!p) return out;
  if (p->decl.is_string()) args_.fail_at(p->line, "parameter \"" + name + "\" expects numbers");
  out.reserve(p->value->numbers.size());
  for (double v : p->value->numbers) {
    if (!std::isfinite(v) || std::fabs(v) > 3.4e38)
      args_.fail_at(p->line, "parameter \"" + name + "\" holds a value that is not a finite float");
    out.push_back(static_cast<float>(v));
  }
  return out;
}

std::string ParamList::get_string(const std::string& name, const std::string& fallback) const {
  const Param* p = find(name);
  if (!p) return fallback;
  if (!p->decl.is_string() || p->value->strings.size() != 1)
    args_.fail_at(p->line, "parameter \"" + name + "\" expects one string");
  return p->value->strings[0];
}

void ParamList::get_int(const std::string& name, long long lo, long long hi, int* out) const {
  const Param* p = find(name);
  if (!p) return;
  if (p->decl.is_string() || p->value->numbers.size() != 1 || !to_int(p->value->numbers[0], lo, hi, out))
    args_.fail_at(p->line, "parameter \"" + name + "\" expects one integer in [" + std::to_string(lo) + ", " +
                               std::to_string(hi) + "]");
}

float ParamList::get_float_checked(const std::string& name, float fallback, bool (*valid)(float),
                                   const std::string& must_be) const {
  const float v = get_float(name, fallback);
  const Param* p = find(name);  // absent: the fallback, which callers keep valid
  if (!valid(v)) args_.fail_at(p ? p->line : args_.request().line, "parameter \"" + name + "\" must be " + must_be);
  return v;
}

}  // namespace mp::rib
