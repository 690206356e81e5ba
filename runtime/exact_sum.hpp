#pragma once
// Exact summation of doubles, for global sums whose bits must not depend on
// how the terms are grouped (DESIGN.md "Parallel model": reductions of
// constant size whose result does not depend on the decomposition).
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
#include <mpi.h>

#include <array>
#include <cstdint>
#include <span>

namespace shatter {

class ExactSum {
 public:
  /// 32-bit digits: 2^-1138 (below the smallest subnormal's 53-bit mantissa)
  /// up to 2^1102 (above the largest double, for the carries of 2^78 of them).
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

/// Every rank's accumulators summed, on every rank (collective over `comm`;
/// size: accumulators.size() x ~570 bytes, independent of the model).
void allreduce(std::span<ExactSum> accumulators, MPI_Comm comm);
/// The same, the result on `root` only (the others' are left as they were).
void reduce_to_root(std::span<ExactSum> accumulators, MPI_Comm comm, int root = 0);

}  // namespace shatter
