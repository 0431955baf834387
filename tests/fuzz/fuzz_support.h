// What every Micropoly fuzz target shares: the planted bug that proves a
// target reports what it finds (tests/fuzz/run_ci.sh) and the exception
// policy (bad input may only end in mp::Error).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace mp::fuzz {

// With MICROPOLY_FUZZ_PLANTED_BUG set in the environment, an input that
// starts with this marker reads one element past a heap array, which
// AddressSanitizer must report. run_ci.sh feeds such an input and fails when
// the target does not crash on it (a harness whose sanitizers or crash
// reporting were silently lost). Without the variable the marker means
// nothing, so ordinary runs and corpora are unaffected.
constexpr char kPlantedBugMarker[] = "MICROPOLY-PLANTED-BUG";

inline void planted_bug(const uint8_t* data, size_t size) {
  static const bool enabled = std::getenv("MICROPOLY_FUZZ_PLANTED_BUG") != nullptr;
  const size_t n = sizeof kPlantedBugMarker - 1;
  if (!enabled || size < n || std::memcmp(data, kPlantedBugMarker, n) != 0) return;
  std::vector<uint8_t> bytes(data, data + n);
  volatile uint8_t past_the_end = bytes.data()[bytes.size()];  // heap-buffer-overflow
  (void)past_the_end;
}

}  // namespace mp::fuzz
