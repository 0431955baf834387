#pragma once
namespace mp {
struct EmbeddedKernelFile {
  const char* name;
  const char* source;
};
extern const EmbeddedKernelFile kEmbeddedKernelFiles[];
extern const int kEmbeddedKernelFileCount;
}  // namespace mp
