#include "contact/radix_sort.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <array>

namespace shatter {
namespace {

constexpr int kDigitBits = 11;
constexpr std::size_t kBuckets = std::size_t(1) << kDigitBits;
constexpr std::size_t kChunk = 16384;  // records per counting task, whatever the threads

/// The 96-bit key's digit d (0 = lowest): bits [11 d, 11 d + 11) of lo | hi << 32.
std::uint32_t digit(const RadixRecord& r, int d) {
  const int shift = d * kDigitBits;
  if (shift + kDigitBits <= 32) return (r.lo >> shift) & (kBuckets - 1);
  if (shift >= 32) return static_cast<std::uint32_t>(r.hi >> (shift - 32)) & (kBuckets - 1);
  return static_cast<std::uint32_t>(((r.hi << (32 - shift)) | (r.lo >> shift)) & (kBuckets - 1));
}

}  // namespace

void radix_sort(std::vector<RadixRecord>& records) {
  const std::size_t n = records.size();
  if (n < 2) return;
  // Which bits differ between keys: (OR of all) xor (AND of all).
  struct Bits {
    std::uint64_t or_hi = 0, and_hi = ~std::uint64_t(0);
    std::uint32_t or_lo = 0, and_lo = ~std::uint32_t(0);
  };
  const Bits bits = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n), Bits{},
      [&](const tbb::blocked_range<std::size_t>& r, Bits b) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          b.or_hi |= records[k].hi, b.and_hi &= records[k].hi;
          b.or_lo |= records[k].lo, b.and_lo &= records[k].lo;
        }
        return b;
      },
      [](Bits a, const Bits& b) {
        a.or_hi |= b.or_hi, a.and_hi &= b.and_hi, a.or_lo |= b.or_lo, a.and_lo &= b.and_lo;
        return a;
      });
  const RadixRecord varying{bits.or_hi ^ bits.and_hi, bits.or_lo ^ bits.and_lo, 0};

  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::array<std::size_t, kBuckets>> offset(chunks);
  std::vector<RadixRecord> other(n);
  std::vector<RadixRecord>* from = &records;
  std::vector<RadixRecord>* to = &other;
  constexpr int kDigits = (96 + kDigitBits - 1) / kDigitBits;
  for (int d = 0; d < kDigits; ++d) {
    if (digit(varying, d) == 0) continue;
    const std::vector<RadixRecord>& src = *from;
    std::vector<RadixRecord>& dst = *to;
    tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
      auto& count = offset[c];
      count.fill(0);
      for (std::size_t k = c * kChunk, e = std::min(n, k + kChunk); k != e; ++k) ++count[digit(src[k], d)];
    });
    // Bucket by bucket, chunk by chunk: where each chunk's records of a bucket go.
    std::size_t at = 0;
    for (std::size_t b = 0; b < kBuckets; ++b)
      for (std::size_t c = 0; c < chunks; ++c) {
        const std::size_t count = offset[c][b];
        offset[c][b] = at;
        at += count;
      }
    tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
      auto& next = offset[c];
      for (std::size_t k = c * kChunk, e = std::min(n, k + kChunk); k != e; ++k) dst[next[digit(src[k], d)]++] = src[k];
    });
    std::swap(from, to);
  }
  if (from != &records) records.swap(*from);
}

}  // namespace shatter
