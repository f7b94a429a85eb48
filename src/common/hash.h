// common: a 64-bit FNV-1a hash (checkpoint checksums, reference
// fingerprints). Hand-written: eight lines, where zlib's CRC-32 would add a
// dependency for no gain at these sizes (32 MB hash in about 30 ms).
#ifndef MIMIC2D_COMMON_HASH_H_
#define MIMIC2D_COMMON_HASH_H_

#include <cstddef>
#include <cstdint>

namespace m2d {

inline constexpr uint64_t kFnv1a64Seed = 14695981039346656037ull;

// Continues `hash` (start from kFnv1a64Seed) over `size` bytes.
inline uint64_t Fnv1a64(const void* data, size_t size,
                        uint64_t hash = kFnv1a64Seed) {
  const unsigned char* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    hash ^= bytes[i];
    hash *= 1099511628211ull;
  }
  return hash;
}

}  // namespace m2d

#endif  // MIMIC2D_COMMON_HASH_H_
