// micropoly-render: renders a RIB file to PNG or EXR.
// Exit codes: 0 success, 1 rendering failed (device, memory), 2 bad usage or input.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "io/image_io.h"
#include "micropoly/error.h"
#include "micropoly/renderer.h"
#include "micropoly/settings_util.h"
#include "rib/rib_reader.h"

namespace {

const char* kUsage =
    "usage: micropoly-render SCENE.rib -o OUT.(png|exr) [--spp N] [--shading-rate R]\n"
    "                        [--device cpu|gpu|INDEX] [--bound-split bounded|breadth]\n"
    "                        [--bound-split-memory MIB] [--bound-split-chain N]\n"
    "                        [--bound-split-steps N] [--shadows on|off]\n"
    "                        [--shadow-memory MIB]\n"
    "                        [--fresh-shadows] [--occlusion-culling on|off] [--sample-culling on|off]\n"
    "                        [--stats FILE.json]\n"
    "                        [--sampler auto|tiles|micropolygons|bins] [--sample-memory MIB]\n"
    "                        [--visibility-first auto|on|off] [--resolver auto|tiles|pixels]\n"
    "                        [--occlusion-waves auto|on|off]\n"
    "                        [--texture-filter-width W]\n"
    "                        [--repeat N] [--readback float|half|none]\n"
    "                        [--allow-path DIR]... [--allow-any-path]\n"
    "       micropoly-render --list-devices\n"
    "A scene may read archives and textures only inside its own folder and the\n"
    "folders given with --allow-path, and its material programs may not include\n"
    "files or use inline assembly; --allow-any-path trusts the scene file and lifts\n"
    "both rules (docs/rib.md, \"Untrusted scene files\").\n";

struct Options {
  std::string scene, output, device, stats, bound_split, shadows, occlusion, sample_culling, sampler, visibility_first,
      resolver;
  std::string occlusion_waves;
  std::string readback;  // float (default), half, none (no image written: benchmarks)
  int spp = 0, repeat = 1, bound_split_chain = 0, bound_split_steps = -1;
  float shading_rate = 0, memory_mib = 0, shadow_memory_mib = 0, sample_memory_mib = 0;
  float texture_filter_width = -1;  // below 0: the scene's
  bool list_devices = false;
  bool fresh_shadows = false;  // every --repeat frame renders its shadow maps anew
  mp::RibReadOptions rib;      // --allow-path, --allow-any-path
};

[[noreturn]] void usage_error(const std::string& why) {
  std::fprintf(stderr, "micropoly-render: %s\n%s", why.c_str(), kUsage);
  std::exit(2);
}

double parse_number(const std::string& flag, const char* text, double lo, double hi) {
  char* end = nullptr;
  double v = std::strtod(text, &end);
  if (!end || *end != '\0' || !(v >= lo && v <= hi))
    usage_error(flag + " expects a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + text + "'");
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) usage_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "-o") o.output = value();
    else if (a == "--spp") o.spp = static_cast<int>(parse_number(a, value(), 1, 1024));
    else if (a == "--shading-rate") o.shading_rate = static_cast<float>(parse_number(a, value(), 1e-3, 1e4));
    else if (a == "--device") o.device = value();
    else if (a == "--bound-split") {
      o.bound_split = value();
      if (o.bound_split != "bounded" && o.bound_split != "breadth") usage_error("--bound-split is bounded or breadth");
    } else if (a == "--bound-split-memory") o.memory_mib = static_cast<float>(parse_number(a, value(), 0.01, 1 << 20));
    else if (a == "--bound-split-chain") o.bound_split_chain = static_cast<int>(parse_number(a, value(), 1, 1024));
    else if (a == "--bound-split-steps") o.bound_split_steps = static_cast<int>(parse_number(a, value(), 0, 1024));
    else if (a == "--shadows") {
      o.shadows = value();
      if (o.shadows != "on" && o.shadows != "off") usage_error("--shadows is on or off");
    } else if (a == "--shadow-memory") o.shadow_memory_mib = static_cast<float>(parse_number(a, value(), 1, 1 << 20));
    else if (a == "--fresh-shadows") o.fresh_shadows = true;
    else if (a == "--sample-culling") {
      o.sample_culling = value();
      if (o.sample_culling != "on" && o.sample_culling != "off") usage_error("--sample-culling is on or off");
    } else if (a == "--occlusion-culling") {
      o.occlusion = value();
      if (o.occlusion != "on" && o.occlusion != "off") usage_error("--occlusion-culling is on or off");
    }
    else if (a == "--sampler") {
      o.sampler = value();
      if (o.sampler != "auto" && o.sampler != "tiles" && o.sampler != "micropolygons" && o.sampler != "bins")
        usage_error("--sampler is auto, tiles, micropolygons or bins");
    } else if (a == "--resolver") {
      o.resolver = value();
      if (o.resolver != "auto" && o.resolver != "tiles" && o.resolver != "pixels")
        usage_error("--resolver is auto, tiles or pixels");
    } else if (a == "--occlusion-waves") {
      o.occlusion_waves = value();
      if (o.occlusion_waves != "auto" && o.occlusion_waves != "on" && o.occlusion_waves != "off")
        usage_error("--occlusion-waves is auto, on or off");
    } else if (a == "--visibility-first") {
      o.visibility_first = value();
      if (o.visibility_first != "auto" && o.visibility_first != "on" && o.visibility_first != "off")
        usage_error("--visibility-first is auto, on or off");
    } else if (a == "--sample-memory") o.sample_memory_mib = static_cast<float>(parse_number(a, value(), 1, 1 << 24));
    else if (a == "--texture-filter-width")
      o.texture_filter_width = static_cast<float>(parse_number(a, value(), 0, 16));
    else if (a == "--stats") o.stats = value();
    else if (a == "--repeat") o.repeat = static_cast<int>(parse_number(a, value(), 1, 10000));
    else if (a == "--readback") {
      o.readback = value();
      if (o.readback != "float" && o.readback != "half" && o.readback != "none")
        usage_error("--readback is float, half or none");
    }
    else if (a == "--list-devices") o.list_devices = true;
    else if (a == "--allow-path") o.rib.allowed_roots.push_back(value());
    else if (a == "--allow-any-path") o.rib.allow_any_path = true;
    else if (!a.empty() && a[0] == '-') usage_error("unknown option " + a);
    else if (o.scene.empty()) o.scene = a;
    else usage_error("more than one scene file given");
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parse(argc, argv);
  try {
    if (o.list_devices) {
      auto devices = mp::list_devices();
      if (devices.empty()) std::puts("no OpenCL devices found");
      for (auto& d : devices)
        std::printf("%d: %s [%s] (%s, %s)\n", d.index, d.name.c_str(), d.type.c_str(), d.platform.c_str(), d.version.c_str());
      return 0;
    }
    if (o.scene.empty()) usage_error("no scene file given");
    mp::RibResult rib;
    try {
      rib = mp::read_rib_file(o.scene, o.rib);
    } catch (const mp::Error& e) {
      std::fprintf(stderr, "micropoly-render: %s\n", e.what());
      return 2;
    }
    for (auto& w : rib.warnings) std::fprintf(stderr, "micropoly-render: warning: %s\n", w.c_str());
    std::string output = o.output.empty() ? rib.display_name : o.output;
    if (output.empty()) usage_error("no output file: give -o or a Display request");
    mp::Scene& scene = rib.scene;
    if (o.spp) mp::set_samples_per_pixel(scene.settings, o.spp);
    if (o.shading_rate > 0) scene.settings.shading_rate = o.shading_rate;
    if (!o.bound_split.empty())
      scene.settings.bound_split = o.bound_split == "breadth" ? mp::BoundSplitMethod::Breadth : mp::BoundSplitMethod::Bounded;
    if (o.memory_mib > 0) scene.settings.bound_split_memory_mib = o.memory_mib;
    if (o.bound_split_chain > 0) scene.settings.bound_split_chain = o.bound_split_chain;
    if (o.bound_split_steps >= 0) scene.settings.bound_split_steps = o.bound_split_steps;
    if (!o.shadows.empty()) scene.settings.shadows = o.shadows == "on";
    if (o.shadow_memory_mib > 0) scene.settings.shadow_memory_mib = o.shadow_memory_mib;
    if (o.fresh_shadows) scene.settings.keep_shadow_pages = false;
    if (!o.occlusion.empty()) scene.settings.occlusion_culling = o.occlusion == "on";
    if (!o.sample_culling.empty()) scene.settings.sample_culling = o.sample_culling == "on";
    if (!o.sampler.empty())
      scene.settings.sampler = o.sampler == "tiles"           ? mp::Sampler::Tiles
                               : o.sampler == "micropolygons" ? mp::Sampler::Micropolygons
                               : o.sampler == "bins"          ? mp::Sampler::Bins
                                                              : mp::Sampler::Auto;
    if (!o.resolver.empty())
      scene.settings.resolver = o.resolver == "tiles"    ? mp::Resolver::Tiles
                                : o.resolver == "pixels" ? mp::Resolver::Pixels
                                                         : mp::Resolver::Auto;
    if (!o.occlusion_waves.empty())
      scene.settings.occlusion_waves = o.occlusion_waves == "on"    ? mp::OcclusionWaves::On
                                       : o.occlusion_waves == "off" ? mp::OcclusionWaves::Off
                                                                    : mp::OcclusionWaves::Auto;
    if (!o.visibility_first.empty())
      scene.settings.visibility_first = o.visibility_first == "on"    ? mp::VisibilityFirst::On
                                        : o.visibility_first == "off" ? mp::VisibilityFirst::Off
                                                                      : mp::VisibilityFirst::Auto;
    if (o.sample_memory_mib > 0) scene.settings.sample_memory_mib = o.sample_memory_mib;
    if (o.texture_filter_width >= 0) scene.settings.texture_filter_width = o.texture_filter_width;
    // Only EXR files hold the Depth and Normal passes.
    auto dot = output.find_last_of('.');
    std::string ext = dot == std::string::npos ? "" : output.substr(dot + 1);
    scene.settings.depth_and_normal_passes = ext == "exr" || ext == "EXR";
    try {
      mp::validate_scene(scene);
    } catch (const mp::Error& e) {
      std::fprintf(stderr, "micropoly-render: %s: %s\n", o.scene.c_str(), e.what());
      return 2;
    }
    if (!o.readback.empty())
      scene.settings.read_back = o.readback == "half"   ? mp::ReadBack::Half
                                 : o.readback == "none" ? mp::ReadBack::None
                                                        : mp::ReadBack::Float;
    // --repeat renders frames back to back, each one's read-back beside the
    // next one's work (Renderer::render_overlapped), into two results in
    // turn; a frame's stats are complete once the next has started. The
    // results outlive the renderer, whose read-back may still write them.
    mp::RenderResult results[2];
    mp::Renderer renderer(o.device);
    std::vector<std::string> frame_stats;
    using Clock = std::chrono::steady_clock;
    Clock::time_point last_start;
    auto ms = [](Clock::time_point from, Clock::time_point to) {
      return std::chrono::duration<double, std::milli>(to - from).count();
    };
    for (int i = 0; i < o.repeat; ++i) {
      const Clock::time_point start = Clock::now();
      if (i) results[(i - 1) % 2].stats.timings_ms.interval = ms(last_start, start);
      renderer.render_overlapped(scene, results[i % 2]);
      if (i) frame_stats.push_back(results[(i - 1) % 2].stats.to_json());
      last_start = start;
    }
    renderer.finish_frame();
    mp::RenderResult& result = results[(o.repeat - 1) % 2];
    result.stats.timings_ms.interval = ms(last_start, Clock::now());
    frame_stats.push_back(result.stats.to_json());
    std::string all_stats;
    if (o.repeat > 1) {
      for (size_t i = 0; i < frame_stats.size(); ++i) all_stats += (i ? ",\n" : "[\n") + frame_stats[i];
      all_stats += "]\n";
    } else {
      all_stats = frame_stats[0];
    }
    if (scene.settings.read_back != mp::ReadBack::None) mp::write_image(output, result);
    if (!o.stats.empty()) {
      std::ofstream f(o.stats);
      if (!f) throw mp::Error("cannot write stats file '" + o.stats + "'");
      f << all_stats;
    }
    return 0;
  } catch (const mp::Error& e) {
    std::fprintf(stderr, "micropoly-render: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "micropoly-render: out of host memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "micropoly-render: %s\n", e.what());
    return 1;
  }
}
