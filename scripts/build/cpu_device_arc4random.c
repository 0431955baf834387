// SPDX-License-Identifier: GPL-3.0-or-later
// arc4random() for a C library older than glibc 2.36, which added it.
//
// Debian 12's LLVM 15 calls arc4random (llvm::sys::Process::GetRandomNumber,
// for unique temporary file names) and so names glibc 2.36. The CPU device
// wheel (scripts/build/cpu_device_wheel.py) clears that version from its copy of
// libLLVM and makes it need this library as well: where the C library has
// arc4random (2.36 and later) the process binds that one, which it finds
// first; on glibc 2.34 and 2.35 (RHEL 9, Ubuntu 22.04) it binds this.
#include <errno.h>
#include <stdint.h>
#include <sys/random.h>

uint32_t arc4random(void) {
  uint32_t value = 0;
  for (;;) {
    ssize_t got = getrandom(&value, sizeof value, 0);
    if (got == (ssize_t)sizeof value) return value;
    if (got < 0 && errno != EINTR) break;
  }
  // getrandom(2) exists from Linux 3.17. Without it, splitmix64 over a
  // counter seeded by an address (ASLR) still serves LLVM's use: temporary
  // file names, retried on a collision.
  static _Atomic uint64_t counter;
  uint64_t z = (uint64_t)(uintptr_t)&counter + counter++ * UINT64_C(0x9e3779b97f4a7c15);
  z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
  z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
  return (uint32_t)((z ^ (z >> 31)) >> 32);
}
