#pragma once
// Counts heap allocations (malloc and everything built on it: operator new, Eigen) made by the calling code while
// an AllocationCounter is alive. Works by interposing malloc in the test binary; AddressSanitizer owns malloc in
// the sanitizer build, so there the counter is unavailable (available() is false) and the real-time checks run in
// the release build.

#include <cstddef>

namespace redres::testing {

/// True when allocations can be counted in this build.
bool allocation_counting_available();

/// Counts allocations between construction and count().
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  /// Allocations so far.
  [[nodiscard]] long count() const;
};

}  // namespace redres::testing
