#pragma once
// Memory for the large arrays of a log read from a file that is already in the disk cache,
// where most of the time goes to page faults: the kernel may back them with huge pages (2 MB)
// instead of thousands of 4 KB ones. Internal to core/io.
#include <sys/mman.h>

#include <cstdint>
#include <vector>

namespace flexarm::textio {

// Asks the kernel to back the whole huge pages inside [p, p + bytes) with huge pages.
inline void adviseHugePages(const void* p, std::size_t bytes) {
  constexpr std::uintptr_t kHuge = 2u << 20;
  const auto b = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
  const auto e = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
  if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
}

// Room for n elements of v, empty, on huge pages where the kernel allows.
template <class T>
void reserveOnHugePages(std::vector<T>& v, std::size_t n) {
  v.clear();
  v.reserve(n);
  adviseHugePages(v.data(), n * sizeof(T));
}

// v sized to n elements, on huge pages where the kernel allows.
template <class T>
void sizeOnHugePages(std::vector<T>& v, std::size_t n) {
  reserveOnHugePages(v, n);
  v.resize(n);
}

}  // namespace flexarm::textio
