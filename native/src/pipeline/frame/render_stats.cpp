#include <cstdio>
#include <string>

#include "micropoly/renderer.h"

namespace mp {
namespace {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

// {"phase": count, ...} in the order given.
std::string json_counts(const std::vector<std::pair<std::string, size_t>>& counts) {
  std::string j = "{";
  for (size_t i = 0; i < counts.size(); ++i)
    j += std::string(i ? ", " : "") + json_string(counts[i].first) + ": " + std::to_string(counts[i].second);
  return j + "}";
}

}  // namespace

std::string RenderStats::to_json() const {
  std::string j = "{\n";
  j += "  \"device\": " + json_string(device) + ",\n";
  j += "  \"resolver\": " + json_string(resolver) + ",\n";
  j += "  \"sampler\": " + json_string(sampler) + ",\n";
  j += "  \"width\": " + std::to_string(width) + ",\n";
  j += "  \"height\": " + std::to_string(height) + ",\n";
  j += "  \"spp\": " + std::to_string(spp) + ",\n";
  j += "  \"patches\": " + std::to_string(patches) + ",\n";
  j += "  \"subpatches_diced\": " + std::to_string(subpatches_diced) + ",\n";
  j += "  \"micropolygons\": " + std::to_string(micropolygons) + ",\n";
  j += "  \"micropolygons_sampled\": " + std::to_string(micropolygons_sampled) + ",\n";
  j += "  \"sample_tests\": " + std::to_string(sample_tests) + ",\n";
  j += "  \"sample_tests_per_sample\": " +
       num(width && height && spp ? double(sample_tests) / (double(width) * double(height) * double(spp)) : 0.0) +
       ",\n";
  j += "  \"sampled_area_px\": " + num(sampled_area_px) + ",\n";
  j += "  \"subpatches_occluded\": " + std::to_string(subpatches_occluded) + ",\n";
  j += "  \"covered_pixels\": " + std::to_string(covered_pixels) + ",\n";
  j += "  \"root_overlap\": " + num(root_overlap) + ",\n";
  j += "  \"occlusion_waves\": " + std::string(occlusion_waves ? "true" : "false") + ",\n";
  j += "  \"waves\": " + std::to_string(waves) + ",\n";
  j += "  \"subpatches_unshaded\": " + std::to_string(subpatches_unshaded) + ",\n";
  j += "  \"depth_complexity\": " + num(covered_pixels ? sampled_area_px / double(covered_pixels) : 0.0) + ",\n";
  j += "  \"micropolygons_per_covered_pixel\": " +
       num(covered_pixels ? double(micropolygons_sampled) / double(covered_pixels) : 0.0) + ",\n";
  j += "  \"bound_split_peak_bytes\": " + std::to_string(bound_split_peak_bytes) + ",\n";
  j += "  \"instances\": " + std::to_string(instances) + ",\n";
  j += "  \"scene_bytes\": " + std::to_string(scene_bytes) + ",\n";
  j += "  \"surface_record_bytes\": " + std::to_string(surface_record_bytes) + ",\n";
  j += "  \"bound_split_launches\": " + std::to_string(bound_split_launches) + ",\n";
  j += "  \"batches\": " + std::to_string(batches) + ",\n";
  j += "  \"host_waits\": " + std::to_string(host_waits) + ",\n";
  j += "  \"host_waits_by_phase\": " + json_counts(host_waits_by_phase) + ",\n";
  j += "  \"kernel_launches\": " + std::to_string(kernel_launches) + ",\n";
  j += "  \"kernel_launches_by_phase\": " + json_counts(kernel_launches_by_phase) + ",\n";
  j += "  \"buckets\": " + std::to_string(buckets) + ",\n";
  j += "  \"program_build_ms\": " + num(program_build_ms) + ",\n";
  j += "  \"program_cache_hit\": " + std::string(program_cache_hit ? "true" : "false") + ",\n";
  j += "  \"cancelled\": " + std::string(cancelled ? "true" : "false") + ",\n";
  j += "  \"scene_reused\": " + std::string(scene_reused ? "true" : "false") + ",\n";
  const ShadowStats& sh = shadows;
  j += "  \"shadows\": {\"lights\": " + std::to_string(sh.lights) +
       ", \"level_bias\": " + std::to_string(sh.level_bias) + ", \"views\": " + std::to_string(sh.views) +
       ", \"pages_requested\": " + std::to_string(sh.pages_requested) +
       ", \"pages_rendered\": " + std::to_string(sh.pages_rendered) +
       ", \"pages_missing\": " + std::to_string(sh.pages_missing) +
       ", \"micropolygons\": " + std::to_string(sh.micropolygons) +
       ", \"subpatches_occluded\": " + std::to_string(sh.subpatches_occluded) +
       ", \"marking_passes\": " + std::to_string(sh.marking_passes) +
       ", \"marking_occluded\": " + std::to_string(sh.marking_occluded) +
       ", \"budget_bytes\": " + std::to_string(sh.budget_bytes) + ", \"peak_bytes\": " + std::to_string(sh.peak_bytes) +
       ", \"batches\": " + std::to_string(sh.batches) + ", \"mark_wall_ms\": " + num(sh.mark_wall_ms) +
       ", \"render_wall_ms\": " + num(sh.render_wall_ms) + ", \"per_light\": [";
  for (size_t i = 0; i < sh.per_light.size(); ++i)
    j += std::string(i ? ", " : "") + "{\"light\": " + std::to_string(sh.per_light[i].light) + ", \"pages\": " +
         std::to_string(sh.per_light[i].pages) + ", \"bytes\": " + std::to_string(sh.per_light[i].bytes) + "}";
  j += "]},\n";
  j += "  \"timings_ms\": {\"upload\": " + num(timings_ms.upload) +
       ", \"bound_split\": " + num(timings_ms.bound_split) + ", \"dice\": " + num(timings_ms.dice) +
       ", \"shade\": " + num(timings_ms.shade) + ", \"sample\": " + num(timings_ms.sample) +
       ", \"resolve\": " + num(timings_ms.resolve) + ", \"readback\": " + num(timings_ms.readback) +
       ", \"shadow_mark\": " + num(timings_ms.shadow_mark) + ", \"shadow\": " + num(timings_ms.shadow) +
       ", \"shadow_bound_split\": " + num(timings_ms.shadow_bound_split) +
       ", \"shadow_dice\": " + num(timings_ms.shadow_dice) + ", \"shadow_sample\": " + num(timings_ms.shadow_sample) +
       ", \"shadows_wall\": " + num(timings_ms.shadows_wall) + ", \"occlusion\": " + num(timings_ms.occlusion) +
       ", \"readback_wait\": " + num(timings_ms.readback_wait) + ", \"interval\": " + num(timings_ms.interval) +
       ", \"total\": " + num(timings_ms.total) + "}\n";
  j += "}\n";
  return j;
}

}  // namespace mp
