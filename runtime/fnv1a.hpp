#pragma once
// FNV-1a, 64 bits (Fowler, Noll, Vo): the hash that checkpoints and part files
// keep of their bytes, to find a flipped or missing byte before anything is
// read from them. Chained: fnv1a(b, nb, fnv1a(a, na)) is the hash of a then b.
#include <cstddef>
#include <cstdint>

namespace shatter {

inline std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h = 1469598103934665603ULL) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 1099511628211ULL;
  }
  return h;
}

}  // namespace shatter
