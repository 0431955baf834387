// Material program fuzz target. A material's node tree reaches the device as
// OpenCL C that the add-on's node compiler (addon/micropoly/node_compiler.py)
// generates: temporaries `float vN = mp_...(...)` calling the node library
// (kernels/materials/mp_node_lib.h, kernels/textures/) on globals, constants
// and earlier temporaries, inside mp_node_displacement and mp_node_surface.
// A RIB file carries the same text (Attribute "micropoly" "string program").
// Each input becomes one such program and goes through the renderer's own
// build path, MaterialPrograms::prepare (assemble_material_program_source,
// then build_program_cached on the default OpenCL device): it must build, or
// fail with mp::Error carrying the compiler's log, and never crash.
//
// Input: 'R' followed by program text is used as it is (real programs from
// the seed corpus, mutated byte-wise with the OpenCL dictionary); any other
// input is decoded as a node program (decode_program below).
//
// One device build per input (PoCL: tens of milliseconds to seconds), so run
// it with a small -max_len. The process keeps one DeviceSession; the binary
// cache is off for material programs (every input would add a file).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <fuzzer/FuzzedDataProvider.h>

#include "cl/device_session.h"
#include "fuzz_support.h"
#include "micropoly/error.h"
#include "pipeline/materials/material_programs.h"

namespace {

// Values a generated function can read: by type, as C expressions.
struct Pool {
  std::vector<std::string> floats{"g->ray_length", "(float)g->backfacing", "(float)g->shadow_ray", "g->P.x",
                                  "g->generated.y"};
  std::vector<std::string> vecs{"g->P", "g->N", "g->generated", "g->I", "g->uv[0]"};
};

class ProgramDecoder {
 public:
  explicit ProgramDecoder(FuzzedDataProvider& in) : in_(in) {}

  std::string program() {
    std::string displacement = function_body(false);
    std::string surface = function_body(true);
    std::string out;
    if (uses_neighbours_) out += "#define MP_NODE_USES_NEIGHBOURS 1\n";
    // The headers the calls need, as the compiler includes them; now and
    // then one is left out (a build error) or included twice (guards).
    for (const std::string& h : headers_) {
      // (Exhausted input reads as 0: the header is then included once.)
      const int choice = in_.ConsumeIntegralInRange<int>(0, 7);
      const int copies = choice == 6 ? 0 : choice == 7 ? 2 : 1;
      for (int k = 0; k < copies; ++k) out += "#include \"textures/" + h + "\"\n";
    }
    out += "float3 mp_node_displacement(const MpNodeGlobals* g) {\n" + displacement + "}\n";
    out += "void mp_node_surface(const MpNodeGlobals* g, MpSurface* s) {\n" + surface + "}\n";
    return out;
  }

 private:
  // Float literals as the node compiler prints them (repr + f), plus the
  // extremes a socket value can hold.
  std::string literal() {
    switch (in_.ConsumeIntegralInRange<int>(0, 7)) {
      case 0: return "0.0f";
      case 1: return "1.0f";
      case 2: return "-1e+30f";
      case 3: return "3.4028234663852886e+38f";
      case 4: return "1e-45f";
      default: {
        char buf[48];
        std::snprintf(buf, sizeof buf, "%.9gf", double(in_.ConsumeFloatingPointInRange<float>(-100.0f, 100.0f)));
        std::string s = buf;
        if (s.find_first_of(".e") == std::string::npos) s.insert(s.size() - 1, ".0");
        return s;
      }
    }
  }
  // Enumerations the compiler passes as int literals, in and around range.
  std::string enumerator() { return std::to_string(in_.ConsumeIntegralInRange<int>(-2, 48)); }
  std::string f() {
    if (in_.ConsumeIntegralInRange<int>(0, 3) == 0) return literal();
    return pick(pool_.floats);
  }
  std::string v() {
    if (in_.ConsumeIntegralInRange<int>(0, 3) == 0) return "(float3)(" + literal() + ", " + literal() + ", " + literal() + ")";
    return pick(pool_.vecs);
  }
  std::string pick(const std::vector<std::string>& from) {
    return from[in_.ConsumeIntegralInRange<size_t>(0, from.size() - 1)];
  }
  std::string temp(const char* type, const std::string& expr) {
    const std::string name = "v" + std::to_string(counter_++);
    body_ += std::string("  ") + type + " " + name + " = " + expr + ";\n";
    (std::string(type) == "float" ? pool_.floats : pool_.vecs).push_back(name);
    return name;
  }
  std::string out_float() {
    const std::string name = "v" + std::to_string(counter_++);
    body_ += "  float " + name + ";\n";
    return name;
  }
  std::string out_vec() {
    const std::string name = "v" + std::to_string(counter_++);
    body_ += "  float3 " + name + ";\n";
    return name;
  }
  void declare_outputs(const std::string& fl, const std::string& ve) {
    pool_.floats.push_back(fl);
    pool_.vecs.push_back(ve);
  }

  // One node: a call into the node library, as node_compiler.py emits it.
  void node() {
    switch (in_.ConsumeIntegralInRange<int>(0, 24)) {
      case 0: temp("float", "mp_math(" + enumerator() + ", " + f() + ", " + f() + ", " + f() + ")"); break;
      case 1:
        temp("float", "mp_map_range(" + enumerator() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() +
                          ", " + f() + ", " + enumerator() + ")");
        break;
      case 2: temp("float", "mp_clamp_node(" + enumerator() + ", " + f() + ", " + f() + ", " + f() + ")"); break;
      case 3: temp("float", "mp_rgb_to_bw(" + v() + ")"); break;
      case 4: temp("float", "mp_nl_clamp01(" + f() + ")"); break;
      case 5: temp("float", "mp_fresnel_node(g, " + f() + ", " + v() + ")"); break;
      case 6: temp("float", "mp_view_cos(g, " + v() + ")"); break;
      case 7: {
        const std::string facing = out_float();
        temp("float", "mp_layer_weight(g, " + f() + ", " + v() + ", &" + facing + ")");
        pool_.floats.push_back(facing);
        break;
      }
      case 8: {
        const std::string value = out_float();
        temp("float3", "mp_vector_math(" + enumerator() + ", " + v() + ", " + v() + ", " + v() + ", " + f() + ", &" +
                           value + ")");
        pool_.floats.push_back(value);
        break;
      }
      case 9: temp("float3", "mp_blend(" + enumerator() + ", " + f() + ", " + v() + ", " + v() + ")"); break;
      case 10: temp("float3", "mp_gamma(" + v() + ", " + f() + ")"); break;
      case 11: temp("float3", "mp_bright_contrast(" + v() + ", " + f() + ", " + f() + ")"); break;
      case 12:
        temp("float3", "mp_hue_saturation(" + f() + ", " + f() + ", " + f() + ", " + f() + ", " + v() + ")");
        break;
      case 13:
        temp("float3", "mp_mapping(" + enumerator() + ", " + v() + ", " + v() + ", " + v() + ", " + v() + ")");
        break;
      case 14: temp("float3", "mp_nl_clamp01_3(" + v() + ")"); break;
      case 15: temp("float3", "(float3)(" + f() + ", " + f() + ", " + f() + ")"); break;
      case 16: temp("float", v() + "." + std::string(1, "xyz"[in_.ConsumeIntegralInRange<int>(0, 2)])); break;
      case 17:
        temp("float3", "mp_blackbody(" + f() + ", " + enumerator() + ", " + v() + ", " + v() + ", " + v() + ")");
        headers_.insert("mp_tex_color.h");
        break;
      case 18:
        temp("float3", "mp_wavelength(" + f() + ", " + v() + ", " + v() + ", " + v() + ")");
        headers_.insert("mp_tex_color.h");
        break;
      case 19: {
        const std::string fac = out_float(), col = out_vec();
        body_ += "  mp_tex_noise(" + v() + ", " + f() + ", " + enumerator() + ", " + enumerator() + ", " +
                 enumerator() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " +
                 f() + ", " + std::to_string(in_.ConsumeIntegralInRange<int>(300, 500)) + ", &" + fac + ", &" + col +
                 ");\n";
        declare_outputs(fac, col);
        headers_.insert("mp_tex_noise.h");
        break;
      }
      case 20: {
        const std::string fac = out_float(), col = out_vec();
        body_ += "  mp_tex_wave(" + v() + ", " + enumerator() + ", " + enumerator() + ", " + enumerator() + ", " +
                 f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " +
                 std::to_string(in_.ConsumeIntegralInRange<int>(300, 500)) + ", &" + fac + ", &" + col + ");\n";
        declare_outputs(fac, col);
        headers_.insert("mp_tex_wave.h");
        break;
      }
      case 21: {
        const std::string d = out_float(), col = out_vec(), pos = out_vec(), w = out_float(), r = out_float();
        body_ += "  mp_tex_voronoi(" + v() + ", " + f() + ", " + enumerator() + ", " + enumerator() + ", " +
                 enumerator() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " +
                 f() + ", " + enumerator() + ", " + std::to_string(in_.ConsumeIntegralInRange<int>(300, 500)) +
                 ", &" + d + ", &" + col + ", &" + pos + ", &" + w + ", &" + r + ");\n";
        declare_outputs(d, col);
        declare_outputs(w, pos);
        pool_.floats.push_back(r);
        headers_.insert("mp_tex_voronoi.h");
        break;
      }
      case 22:
        temp("float", "mp_tex_checker(" + v() + ", " + f() + ")");
        headers_.insert("mp_tex_pattern.h");
        break;
      case 23:
        temp("float3", "mp_tex_magic(" + v() + ", " + f() + ", " + enumerator() + ", " + f() + ")");
        headers_.insert("mp_tex_pattern.h");
        break;
      default:
        uses_neighbours_ = true;
        temp("float3", "mp_bump(g, " + f() + ", " + f() + ", " + f() + ", " + f() + ", " + f() + ", " +
                           enumerator() + ", " + v() + ")");
        break;
    }
  }

  // A closure added to the surface, as shader nodes add them.
  void closure() {
    const std::string slot = enumerator();
    switch (in_.ConsumeIntegralInRange<int>(0, 8)) {
      case 0: body_ += "  mp_add_diffuse(s, " + v() + ", " + slot + ", " + f() + ");\n"; break;
      case 1: body_ += "  mp_add_emission(s, " + v() + ");\n"; break;
      case 2:
        body_ += "  mp_add_glossy(s, " + v() + ", " + slot + ", " + f() + ", " + f() + ", " + v() + ", " +
                 enumerator() + ", " + v() + ", " + v() + ", " + enumerator() + ");\n";
        break;
      case 3: body_ += "  mp_add_transparent(s, " + v() + ");\n"; break;
      case 4: body_ += "  mp_add_holdout(s, " + v() + ");\n"; break;
      case 5: body_ += "  mp_add_sheen(s, " + v() + ", " + slot + ", " + f() + ", " + enumerator() + ");\n"; break;
      case 6:
        body_ += "  mp_add_toon(s, " + v() + ", " + slot + ", " + f() + ", " + f() + ", " + enumerator() + ");\n";
        break;
      case 7:
        body_ += "  mp_add_refraction(s, " + v() + ", " + slot + ", " + f() + ", " + f() + ", " + enumerator() + ");\n";
        break;
      default:
        body_ += "  mp_add_glass(s, " + v() + ", " + slot + ", " + f() + ", " + f() + ", " + enumerator() + ");\n";
        break;
    }
  }

  std::string function_body(bool surface) {
    body_.clear();
    pool_ = Pool{};
    const int nodes = in_.ConsumeIntegralInRange<int>(0, 12);
    for (int i = 0; i < nodes && in_.remaining_bytes() > 0; ++i) node();
    if (surface) {
      const int closures = in_.ConsumeIntegralInRange<int>(0, 4);
      for (int i = 0; i < closures; ++i) closure();
      return body_;
    }
    return body_ + "  return " + v() + ";\n";
  }

  FuzzedDataProvider& in_;
  Pool pool_;
  std::string body_;
  int counter_ = 0;
  bool uses_neighbours_ = false;
  std::set<std::string> headers_;
};

mp::DeviceSession& session() {
  static const std::unique_ptr<mp::DeviceSession> s = [] {
    auto made = std::make_unique<mp::DeviceSession>("");
    // The main program came from (or went into) the binary cache; material
    // programs bypass it from here on, through a folder that cannot exist.
    setenv("MICROPOLY_CACHE_DIR", "/dev/null/micropoly-fuzz", 1);
    return made;
  }();
  return *s;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  setenv("POCL_KERNEL_CACHE", "0", 0);  // PoCL's own cache would grow by one entry per input
  try {
    session();
  } catch (const mp::Error& e) {
    std::fprintf(stderr, "material program fuzzing needs an OpenCL device: %s\n", e.what());
    std::exit(2);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mp::fuzz::planted_bug(data, size);
  mp::Scene scene;
  if (size > 0 && data[0] == 'R') {
    scene.material_programs.push_back({"fuzz", std::string(reinterpret_cast<const char*>(data) + 1, size - 1)});
  } else {
    FuzzedDataProvider in(data, size);
    scene.material_programs.push_back({"fuzz", ProgramDecoder(in).program()});
  }
  // MICROPOLY_FUZZ_PRINT_PROGRAM=1 shows what an input became (reproducing
  // a finding by hand, checking that the decoder writes programs that build).
  static const bool print = std::getenv("MICROPOLY_FUZZ_PRINT_PROGRAM") != nullptr;
  if (print) std::fprintf(stderr, "--- program ---\n%s--- end ---\n", scene.material_programs[0].source.c_str());
  mp::Material material;
  material.program = 0;
  // Displacing only: the tree's program is built whole either way (both
  // its kernels), while a shading material would also build the light
  // program, whose source no input changes (and whose build, kept by the
  // MaterialPrograms, would only add a fixed cost to every input).
  material.program_shades = false;
  material.program_displaces = true;
  scene.materials.push_back(material);
  mp::MaterialPrograms programs(session());
  mp::RenderStats stats;
  try {
    programs.prepare(scene, stats);
    if (print) std::fprintf(stderr, "built\n");
  } catch (const mp::Error& e) {
    if (print) std::fprintf(stderr, "refused: %.300s\n", e.what());
    // A refused program must say why: the compiler's log follows the
    // renderer's own sentence.
    if (std::string(e.what()).find("did not compile") == std::string::npos) {
      std::fprintf(stderr, "material program failed without its build log: %s\n", e.what());
      __builtin_trap();
    }
  }
  return 0;
}
