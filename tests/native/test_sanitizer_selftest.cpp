// Planted bugs proving that a sanitized build turns memory and undefined-
// behaviour errors into a failed run rather than a silent one
// (scripts/check_sanitized.sh, docs/reliability.md). CMakeLists.txt compiles
// this file only when MICROPOLY_SANITIZE is set, and defines
// MICROPOLY_SANITIZE_ADDRESS / MICROPOLY_SANITIZE_UNDEFINED for the sanitizers
// present. Each bug runs in a death-test child process, so the suite itself
// stays clean.
#include <gtest/gtest.h>

#include <climits>
#include <memory>

#if !defined(MICROPOLY_SANITIZE_ADDRESS) && !defined(MICROPOLY_SANITIZE_UNDEFINED)
#error "test_sanitizer_selftest.cpp belongs only in a build with MICROPOLY_SANITIZE set"
#endif

namespace {

// Death tests fork; earlier tests in the same process may have left OpenCL
// driver threads running, so the child re-executes the binary instead
// ("threadsafe" style, GoogleTest's advanced guide, "Death Tests and Threads").
class SanitizerSelfTest : public ::testing::Test {
 protected:
  void SetUp() override { ::testing::FLAGS_gtest_death_test_style = "threadsafe"; }
};

// Volatile operands keep the compiler from proving the bugs at build time, and
// volatile results keep it from deleting the unused faulty operation (gcc -O2
// does, before its sanitizer instrumentation runs).
#if defined(MICROPOLY_SANITIZE_ADDRESS)
void read_past_end() {
  volatile int count = 4;
  std::unique_ptr<int[]> values(new int[count]());
  volatile int index = count;  // one past the last element
  volatile int read = values[index];
  (void)read;
}

TEST_F(SanitizerSelfTest, HeapBufferOverflowAborts) {
  EXPECT_DEATH(read_past_end(), "AddressSanitizer: heap-buffer-overflow");
}
#endif

#if defined(MICROPOLY_SANITIZE_UNDEFINED)
void add_past_int_max() {
  volatile int largest = INT_MAX;
  volatile int one = 1;
  volatile int sum = largest + one;
  (void)sum;
}

TEST_F(SanitizerSelfTest, SignedIntegerOverflowAborts) {
  EXPECT_DEATH(add_past_int_max(), "runtime error: signed integer overflow");
}
#endif

}  // namespace
