// The heap trimmer (server/heap_trim.hpp) against the process's resident set as the kernel reports
// it: freed heap that glibc would keep comes back to the system once a requested trim has run.
#include "server/heap_trim.hpp"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace galpha::server {
namespace {

size_t ResidentBytes() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::strtoull(line.c_str() + 6, nullptr, 10) * 1024;
  }
  return 0;
}

constexpr size_t kMiB = size_t{1} << 20;

TEST(HeapTrimTest, FreedHeapGoesBackToTheSystemAfterARequestedTrim) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's allocator keeps its own heap: malloc_trim has nothing to trim";
#endif
  // 256 MiB in 64 KiB blocks, under glibc's mmap threshold (128 KiB), so they come from the heap,
  // then one small block after them that pins the heap's top; and free's own trimming of the top
  // off (M_TRIM_THRESHOLD), in case the small block came from below: free alone cannot shrink the
  // heap.
  ASSERT_EQ(mallopt(M_TRIM_THRESHOLD, 1 << 30), 1);
  constexpr size_t kBlock = 64 * 1024;
  constexpr size_t kBlocks = 4096;
  std::vector<void*> blocks(kBlocks);
  for (void*& block : blocks) {
    block = std::malloc(kBlock);
    ASSERT_NE(block, nullptr);
    std::memset(block, 1, kBlock);
  }
  void* pin = std::malloc(64);
  ASSERT_NE(pin, nullptr);
  std::memset(pin, 1, 64);
  const size_t filled = ResidentBytes();
  for (void* block : blocks) std::free(block);
  const size_t freed = ResidentBytes();
  // The premise: glibc kept the freed blocks (else this test would prove nothing).
  ASSERT_GT(freed + 64 * kMiB, filled) << "glibc gave the blocks back on free; resident " << freed / kMiB << " MiB, "
                                       << filled / kMiB << " MiB before the frees";

  ReturnFreedHeapMemory();
  WaitForHeapTrims();
  const size_t trimmed = ResidentBytes();
  EXPECT_LT(trimmed + 192 * kMiB, freed) << "resident " << trimmed / kMiB << " MiB after the trim, " << freed / kMiB
                                         << " MiB before it";
  std::free(pin);
}

TEST(HeapTrimTest, WaitingWithNoRequestReturnsAtOnce) {
  WaitForHeapTrims();
  ReturnFreedHeapMemory();
  ReturnFreedHeapMemory();
  WaitForHeapTrims();
  WaitForHeapTrims();
}

}  // namespace
}  // namespace galpha::server
