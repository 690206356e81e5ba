#pragma once
// The one comparison helper of the regression and invariant tests (STYLE.md):
// |value - ref| <= atol + rtol |ref|.
#include <gtest/gtest.h>

#include <cmath>

namespace shatter::test {

inline ::testing::AssertionResult close(double value, double ref, double rtol, double atol = 0.0) {
  const double tol = atol + rtol * std::abs(ref);
  if (std::abs(value - ref) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "value " << value << " differs from " << ref << " by "
                                       << std::abs(value - ref) << " > tolerance " << tol;
}

}  // namespace shatter::test

#define EXPECT_CLOSE(value, ref, rtol, atol) EXPECT_TRUE(::shatter::test::close((value), (ref), (rtol), (atol)))
