#pragma once
// Exact summation of doubles, for global sums whose bits must not depend on
// how the terms are grouped (DESIGN.md "Parallel model": reductions of
// constant size whose result does not depend on the decomposition). The MPI
// reductions of accumulators are in runtime/global_sum.hpp.
//
// Every finite double is an integer multiple of 2^-1074, below 2^1024, so a
// fixed-point integer of about 2100 bits holds any sum of them exactly
// (Kulisch's long accumulator: U. Kulisch, Computer Arithmetic and Validity,
// de Gruyter 2008, ch. 8; the same idea as ReproBLAS's binned sums, which
// keep only the top bins). Here the integer is kDigits signed 64-bit digits
// of 32 bits each (digit i weighs 2^(32 i - kBias)); an add touches three
// digits and no carry runs until normalize(), which the 31 spare bits of each
// digit allow to wait 2^30 adds. Addition of accumulators is integer addition,
// hence associative: any split of the terms over threads and ranks, combined
// in any order, gives the same integer, and value() rounds it to the same
// double. Infinities and NaNs are summed apart (their IEEE sum is order
// independent too: NaN absorbs everything, inf + -inf is NaN).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>

namespace shatter {

class ExactSum {
 public:
  /// 32-bit digits from 2^-1138 up (a double's lowest bit, 2^-1074, lands
  /// in digit 2); the top digit's 63 bits reach 2^1133, room for the sum of
  /// 2^109 of the largest doubles.
  static constexpr int kDigits = 70;
  static constexpr int kBias = 1138;

  void add(double x);
  ExactSum& operator+=(double x) {
    add(x);
    return *this;
  }
  ExactSum& operator+=(const ExactSum& o);
  /// The sum rounded to a double: a function of the exact sum only (digits in
  /// canonical form), within 2 ulp of it.
  double value() const;
  /// Carries propagated: every digit but the top one in [0, 2^32), the top
  /// one carries the sign. The canonical form of the integer.
  void normalize();

  /// The digits (normalize() first to send them: then they add without overflow).
  std::span<std::int64_t> digits() { return digits_; }
  std::span<const std::int64_t> digits() const { return digits_; }
  /// Sum of the non-finite terms (0 if none).
  double special() const { return special_; }
  void set_special(double s) { special_ = s; }

 private:
  std::array<std::int64_t, kDigits> digits_{};
  double special_ = 0;
  std::int32_t pending_ = 0;  ///< adds since the last normalize()
};


inline void ExactSum::add(double x) {
  // The bits of x: sign, biased exponent, mantissa (no frexp: 2.3 ns per add
  // instead of 11 on this machine).
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  if (biased == 0x7ff) {  // inf or NaN
    special_ += x;
    return;
  }
  std::uint64_t mantissa = bits & ((std::uint64_t{1} << 52) - 1);
  if (biased != 0) mantissa |= std::uint64_t{1} << 52;  // normal: the hidden bit
  // |x| = mantissa 2^(max(biased, 1) - 1075) = mantissa 2^(p - kBias), p >= 64.
  const int p = (biased != 0 ? biased : 1) - 1075 + kBias;
  const int i = p >> 5;
  const unsigned __int128 u = static_cast<unsigned __int128>(mantissa) << (p & 31);
  const std::int64_t sign = -static_cast<std::int64_t>(bits >> 63);  // 0 or -1: (v ^ sign) - sign = +-v
  digits_[i] += (static_cast<std::int64_t>(u & 0xffffffffu) ^ sign) - sign;
  digits_[i + 1] += (static_cast<std::int64_t>((u >> 32) & 0xffffffffu) ^ sign) - sign;
  digits_[i + 2] += (static_cast<std::int64_t>(u >> 64) ^ sign) - sign;
  if (++pending_ == (1 << 30)) normalize();
}

inline void ExactSum::normalize() {
  for (int i = 0; i + 1 < kDigits; ++i) {
    const std::int64_t carry = digits_[i] >> 32;  // floor division by 2^32
    digits_[i] -= carry * (std::int64_t{1} << 32);
    digits_[i + 1] += carry;
  }
  pending_ = 0;
}

inline ExactSum& ExactSum::operator+=(const ExactSum& o) {
  ExactSum b = o;
  b.normalize();
  normalize();
  for (int i = 0; i < kDigits; ++i) digits_[i] += b.digits_[i];
  special_ += b.special_;
  normalize();
  return *this;
}

inline double ExactSum::value() const {
  if (special_ != 0 || std::isnan(special_)) return special_;
  ExactSum a = *this;
  a.normalize();
  const bool negative = a.digits_[kDigits - 1] < 0;
  if (negative) {
    for (std::int64_t& d : a.digits_) d = -d;
    a.normalize();
  }
  int top = kDigits - 1;
  while (top >= 0 && a.digits_[top] == 0) --top;
  if (top < 0) return 0.0;
  // The top four digits (>= 97 significant bits), smallest first: non-negative
  // terms, each rounding by at most half an ulp of the partial sum.
  double r = 0;
  for (int i = std::max(0, top - 3); i <= top; ++i)
    r += std::ldexp(static_cast<double>(a.digits_[i]), 32 * i - kBias);
  return negative ? -r : r;
}

}  // namespace shatter
