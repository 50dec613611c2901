#include "alloc_counter.hpp"

#include <execinfo.h>
#include <atomic>
#include <cstdlib>

#if defined(__SANITIZE_ADDRESS__)
#define REDRES_COUNT_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define REDRES_COUNT_ALLOCATIONS 0
#endif
#endif
#ifndef REDRES_COUNT_ALLOCATIONS
#define REDRES_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
inline void note() {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    // REDRES_DEBUG_ALLOC=1: each counted allocation's call stack on stderr (pipe through c++filt), to find it.
    if (std::getenv("REDRES_DEBUG_ALLOC") != nullptr) {
      g_counting.store(false);
      void* frames[40];
      const int n = backtrace(frames, 40);
      backtrace_symbols_fd(frames, n, 2);
      g_counting.store(true);
    }
  }
}
}  // namespace

#if REDRES_COUNT_ALLOCATIONS
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);

void* malloc(std::size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(std::size_t k, std::size_t n) {
  note();
  return __libc_calloc(k, n);
}
void* realloc(void* p, std::size_t n) {
  note();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t a, std::size_t n) {
  note();
  return __libc_memalign(a, n);
}
void* aligned_alloc(std::size_t a, std::size_t n) {
  note();
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) {
  note();
  *out = __libc_memalign(a, n);
  return *out == nullptr ? 12 /* ENOMEM */ : 0;
}
}
#endif

namespace redres::testing {

bool allocation_counting_available() { return REDRES_COUNT_ALLOCATIONS != 0; }

AllocationCounter::AllocationCounter() {
  g_allocations.store(0);
  g_counting.store(true);
}
AllocationCounter::~AllocationCounter() { g_counting.store(false); }
long AllocationCounter::count() const { return g_allocations.load(); }

}  // namespace redres::testing
