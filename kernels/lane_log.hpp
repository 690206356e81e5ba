#pragma once
// Natural log of the lane kernels' det F, vectorised across the lanes.
#include <Eigen/Core>

#include <cmath>

namespace shatter {

/// Values per call of Eigen's packet log in lane_log: 8 doubles are one
/// AVX-512 vector or two AVX ones, so every value goes through the packet
/// path (no scalar head or tail).
inline constexpr int kLogWidth = 8;

/// y[l] = ln x[l] for the N lanes. With AVX (the avx2 and avx512 widths):
/// Eigen's packet log (plog: Cephes' log(1 + f) = f - f^2/2 + f^3 P(f)/Q(f)
/// after reducing x to 2^e (1 + f), sqrt(1/2) <= 1 + f < sqrt(2); within 1.5
/// ulp of the exact log on the det F range of the kernels,
/// tests/kernels/test_lane_log.cpp), kLogWidth values per call, lanes past N
/// padded with 1: every value takes the same instructions whatever its
/// position and N (an aligned fixed-size array of kLogWidth: Eigen's
/// vectorised loop from the first value to the last), so an element's ln J
/// has the same bits in a group of 8 and alone (ranks x threads
/// determinism). 1.0 ns per value at avx512, 1.5 ns at avx2, against 2.5 -
/// 2.9 ns for glibc's scalar log. Without AVX (SSE, the baseline width:
/// two doubles per vector) Eigen's packet log takes 3.8 ns per value, so
/// there it is glibc's std::log, value by value (docs/performance.md, "A
/// vectorised log"). x <= 0 gives NaN (0: -inf), as std::log.
template <int N>
[[gnu::always_inline]] inline void lane_log(const double (&x)[N], double (&y)[N]) {
#ifdef EIGEN_VECTORIZE_AVX
  using Block = Eigen::Array<double, kLogWidth, 1>;
  for (int l0 = 0; l0 < N; l0 += kLogWidth) {
    Block a;
    for (int l = 0; l < kLogWidth; ++l) a[l] = l0 + l < N ? x[l0 + l] : 1.0;
    // GCC 12 warns that its own AVX-512 intrinsics use an uninitialised
    // vector (the _mm512_undefined_pd they start masked operations from).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
    const Block r = a.log();
#pragma GCC diagnostic pop
    for (int l = 0; l < kLogWidth && l0 + l < N; ++l) y[l0 + l] = r[l];
  }
#else
  for (int l = 0; l < N; ++l) y[l] = std::log(x[l]);
#endif
}

}  // namespace shatter
