// Large arrays on transparent huge pages. The first write to each page of a fresh array faults
// it in; an 8192^2 byte mask (64 MiB) is 16,384 faults of 4 KiB, which on the 2-core development
// VM cost about 12 us each (190 ms for the array, more than the work done on it), and 32 faults
// of 2 MiB on huge pages (6 ms). Linux gives huge pages only to ranges advised so when its
// setting is "madvise" (the usual default), so the arrays of supersampled masks, distance
// transforms and per-pixel hits ask for them before they are first written. Elsewhere the
// advice is a no-op; the contents and results never depend on it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/core/image.h"
#include "render/core/mask.h"

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace limn::render {

// Arrays smaller than this keep ordinary pages (a huge page would mostly be unused).
inline constexpr size_t kHugePageMinBytes = size_t{4} << 20;

// Advises the whole 2 MiB pages inside [data, data + bytes) to be huge pages when first touched.
inline void adviseHugePages(const void* data, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (bytes < kHugePageMinBytes) return;
  constexpr uintptr_t kHuge = uintptr_t{2} << 20;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

// `v` resized to `n` copies of `fill` in a fresh allocation advised to huge pages before the
// fill writes it.
template <typename Vector>
void assignOnHugePages(Vector& v, size_t n, const typename Vector::value_type& fill) {
  Vector fresh;
  fresh.reserve(n);
  adviseHugePages(fresh.data(), n * sizeof(typename Vector::value_type));
  fresh.resize(n, fill);
  v.swap(fresh);
}

// Image(w, h, c, fill) on huge pages.
inline Image imageOnHugePages(int w, int h, int c, float fill = 0.0f) {
  Image image;
  image.width = w;
  image.height = h;
  image.channels = c;
  assignOnHugePages(image.pixels, static_cast<size_t>(w) * h * c, fill);
  return image;
}

// Mask(w, h), all uncovered, on huge pages.
inline Mask maskOnHugePages(int w, int h) {
  Mask mask;
  mask.width = w;
  mask.height = h;
  assignOnHugePages(mask.covered, static_cast<size_t>(w) * h, uint8_t{0});
  return mask;
}

}  // namespace limn::render
