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
  Amplitude table;
  table.form = Amplitude::Form::table;
  table.table = {{1.0, 0.0}, {2.0, 4.0}, {4.0, -2.0}};
  const Amplitude constant, ramp = make(Amplitude::Form::ramp, 0, 2.0), smooth = make(Amplitude::Form::smooth_step, 1.0, 3.0),
                  sine = make(Amplitude::Form::half_sine, 1.0, 3.0);
  // {amplitude, t, value(t), rate(t)}: tables held before the first point and after the
  // last; the smooth step's middle and its flat ends; the half sine's peak and ends.
  const struct {
    const Amplitude& a;
    double t, value, rate;
  } cases[] = {{constant, 3.0, 1.0, 0.0}, {table, 0.0, 0.0, 0.0},  {table, 1.5, 2.0, 4.0},
               {table, 3.0, 1.0, -3.0},     {table, 9.0, -2.0, 0.0}, {ramp, 0.0, 0.0, 0.5},
               {ramp, 1.0, 0.5, 0.5},       {ramp, 5.0, 1.0, 0.0},   {smooth, 0.5, 0.0, 0.0},
               {smooth, 1.0, 0.0, 0.0},     {smooth, 2.0, 0.5, 0.9375}, {smooth, 3.0, 1.0, 0.0},
               {smooth, 3.5, 1.0, 0.0},     {sine, 0.5, 0.0, 0.0},   {sine, 2.0, 1.0, 0.0},
               {sine, 3.0, 0.0, -std::numbers::pi / 2}, {sine, 3.5, 0.0, 0.0}};
  for (const auto& c : cases) {
    EXPECT_NEAR(c.a.value(c.t), c.value, 1e-15) << "form " << int(c.a.form) << ", t = " << c.t;
    EXPECT_NEAR(c.a.rate(c.t), c.rate, 1e-15) << "form " << int(c.a.form) << ", t = " << c.t;
  }
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
