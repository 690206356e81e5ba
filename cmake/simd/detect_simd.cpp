// Run once at configure time (cmake/simd.cmake): prints the widest SIMD level
// of shatter's list that the build machine's CPU supports.
#include <cstdio>

int main() {
  __builtin_cpu_init();
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl") &&
                  __builtin_cpu_supports("avx512cd");
  std::puts(v4 ? "avx512" : v3 ? "avx2" : "baseline");
  return 0;
}
