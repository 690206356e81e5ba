// Time functions (kernels/amplitude.hpp): each form's defining values, its
// continuity, and rate() against central differences of value().
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "kernels/amplitude.hpp"

using shatter::Amplitude;

namespace {

Amplitude make(Amplitude::Form form, double t0, double t1) {
  Amplitude a;
  a.form = form;
  a.t0 = t0;
  a.t1 = t1;
  return a;
}

}  // namespace

TEST(Amplitude, FormsTakeTheirDefiningValues) {
  EXPECT_EQ(Amplitude{}.value(3.0), 1.0);
  EXPECT_EQ(Amplitude{}.rate(3.0), 0.0);
  Amplitude table;
  table.form = Amplitude::Form::table;
  table.table = {{1.0, 0.0}, {2.0, 4.0}, {4.0, -2.0}};
  EXPECT_EQ(table.value(0.0), 0.0);   // held before the first point
  EXPECT_EQ(table.value(1.5), 2.0);
  EXPECT_EQ(table.value(3.0), 1.0);
  EXPECT_EQ(table.value(9.0), -2.0);  // held after the last
  EXPECT_EQ(table.rate(1.5), 4.0);
  EXPECT_EQ(table.rate(3.0), -3.0);
  EXPECT_EQ(table.rate(9.0), 0.0);
  const Amplitude ramp = make(Amplitude::Form::ramp, 0, 2.0);
  EXPECT_EQ(ramp.value(0.0), 0.0);
  EXPECT_EQ(ramp.value(1.0), 0.5);
  EXPECT_EQ(ramp.value(5.0), 1.0);
  const Amplitude smooth = make(Amplitude::Form::smooth_step, 1.0, 3.0);
  EXPECT_EQ(smooth.value(0.5), 0.0);
  EXPECT_DOUBLE_EQ(smooth.value(2.0), 0.5);
  EXPECT_EQ(smooth.value(3.5), 1.0);
  EXPECT_EQ(smooth.rate(1.0), 0.0);
  EXPECT_EQ(smooth.rate(3.0), 0.0);
  const Amplitude sine = make(Amplitude::Form::half_sine, 1.0, 3.0);
  EXPECT_EQ(sine.value(0.5), 0.0);
  EXPECT_DOUBLE_EQ(sine.value(2.0), 1.0);
  EXPECT_NEAR(sine.value(3.0), 0.0, 1e-15);
  EXPECT_EQ(sine.value(3.5), 0.0);
}

TEST(Amplitude, RatesMatchCentralDifferences) {
  Amplitude table;
  table.form = Amplitude::Form::table;
  table.table = {{0.0, 1.0}, {1.0, 3.0}, {2.5, 0.0}};
  for (const Amplitude& a : {table, make(Amplitude::Form::ramp, 0, 2.0), make(Amplitude::Form::smooth_step, 0.5, 2.0),
                             make(Amplitude::Form::half_sine, 0.25, 2.0)})
    for (double t = 0.07; t < 3.0; t += 0.1) {  // (off the corners at 0.25, 0.5, 1, 2, 2.25, 2.5)
      const double h = 1e-6;
      const double fd = (a.value(t + h) - a.value(t - h)) / (2 * h);
      EXPECT_NEAR(a.rate(t), fd, 1e-6 * (1 + std::abs(fd))) << "form " << int(a.form) << ", t = " << t;
    }
}
