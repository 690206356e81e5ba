#pragma once
// Time functions of prescribed values and loads (scene key `amplitude`): the
// prescribed value at time t is value * a(t). Forms (t in s):
//   constant      a = 1 (no amplitude given)
//   table         piecewise linear through [t_k, a_k] (t_k increasing), held
//                 constant before the first and after the last point
//   ramp          a = t / t_r up to t_r, then 1
//   smooth_step   0 before t0, 1 after t1, between the quintic
//                 s^3 (10 - 15 s + 6 s^2), s = (t - t0) / (t1 - t0), whose
//                 first and second derivatives vanish at both ends (the
//                 "smooth step" of Abaqus, Analysis User's Guide 34.1.2)
//   half_sine     sin(pi (t - t0) / d) for t0 <= t <= t0 + d, 0 elsewhere
// rate(t) is da/dt (the right-hand derivative at a table's or ramp's corner).
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace shatter {

struct Amplitude {
  enum class Form { constant, table, ramp, smooth_step, half_sine };
  Form form = Form::constant;
  std::vector<std::array<double, 2>> table;  ///< [t_k, a_k], t_k strictly increasing (table)
  double t0 = 0, t1 = 0;                     ///< ramp: t1 = t_r; smooth_step: [t0, t1]; half_sine: t0, t1 = t0 + d

  friend bool operator==(const Amplitude&, const Amplitude&) = default;

  double value(double t) const {
    switch (form) {
      case Form::constant:
        return 1.0;
      case Form::table: {
        if (t <= table.front()[0]) return table.front()[1];
        for (std::size_t k = 1; k < table.size(); ++k)
          if (t < table[k][0]) {
            const auto& [ta, aa] = table[k - 1];
            const auto& [tb, ab] = table[k];
            return aa + (ab - aa) * ((t - ta) / (tb - ta));
          }
        return table.back()[1];
      }
      case Form::ramp:
        return t >= t1 ? 1.0 : t <= 0 ? 0.0 : t / t1;
      case Form::smooth_step: {
        if (t <= t0) return 0.0;
        if (t >= t1) return 1.0;
        const double s = (t - t0) / (t1 - t0);
        return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
      }
      case Form::half_sine:
        return t < t0 || t > t1 ? 0.0 : std::sin(std::numbers::pi * (t - t0) / (t1 - t0));
    }
    return 1.0;
  }

  double rate(double t) const {
    switch (form) {
      case Form::constant:
        return 0.0;
      case Form::table:
        for (std::size_t k = 1; k < table.size(); ++k)
          if (t >= table[k - 1][0] && t < table[k][0])
            return (table[k][1] - table[k - 1][1]) / (table[k][0] - table[k - 1][0]);
        return 0.0;
      case Form::ramp:
        return t >= 0 && t < t1 ? 1.0 / t1 : 0.0;
      case Form::smooth_step: {
        if (t <= t0 || t >= t1) return 0.0;
        const double s = (t - t0) / (t1 - t0);
        return 30.0 * s * s * (1.0 - s) * (1.0 - s) / (t1 - t0);
      }
      case Form::half_sine:
        return t < t0 || t > t1 ? 0.0
                                : std::numbers::pi / (t1 - t0) * std::cos(std::numbers::pi * (t - t0) / (t1 - t0));
    }
    return 0.0;
  }
};

}  // namespace shatter
