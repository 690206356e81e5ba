# SIMD width of the Release build (docs/performance.md "SIMD width"):
#   baseline  -march=x86-64-v2 (SSE4.2: 2 doubles per vector, no FMA), runs on any x86-64 of the last decade
#   avx2      -march=x86-64-v3 (AVX2 + FMA: 4 doubles)
#   avx512    -march=x86-64-v4 (AVX-512 F/DQ/BW/VL/CD: 8 doubles)
#   native    -march=native (every extension of the build machine)
# Default: the widest of baseline/avx2/avx512 that the build machine runs,
# detected at configure time. Where the width has FMA, floating-point
# contraction is off (-ffp-contract=off): a kernel is the same expression in
# its 1-lane and its N-lane form, so an element gives the same bits whichever
# group it falls in (ranks x threads determinism). (baseline has no FMA to
# contract to: its flags are those of the builds before this option.) Bits
# may differ between widths (docs/physics.md).
set(_shatter_simd_levels native avx2 avx512 baseline)
if(NOT DEFINED CACHE{SHATTER_SIMD})
  try_run(_simd_run _simd_compiled ${CMAKE_BINARY_DIR}/simd_detect ${CMAKE_CURRENT_LIST_DIR}/simd/detect_simd.cpp
          RUN_OUTPUT_VARIABLE _simd_detected)
  string(STRIP "${_simd_detected}" _simd_detected)
  if(NOT _simd_compiled OR NOT _simd_run EQUAL 0 OR NOT _simd_detected IN_LIST _shatter_simd_levels)
    set(_simd_detected baseline)
  endif()
  set(SHATTER_SIMD ${_simd_detected} CACHE STRING "SIMD width of the Release build: native, avx2, avx512 or baseline")
  message(STATUS "shatter: SIMD width detected on this machine: ${_simd_detected}")
endif()
set_property(CACHE SHATTER_SIMD PROPERTY STRINGS ${_shatter_simd_levels})
if(NOT SHATTER_SIMD IN_LIST _shatter_simd_levels)
  message(FATAL_ERROR "SHATTER_SIMD=${SHATTER_SIMD}: expected one of ${_shatter_simd_levels}")
endif()
set(_march_baseline x86-64-v2)
set(_march_avx2 x86-64-v3)
set(_march_avx512 x86-64-v4)
set(_march_native native)
set(SHATTER_SIMD_FLAGS "-march=${_march_${SHATTER_SIMD}}")
if(NOT SHATTER_SIMD STREQUAL "baseline")
  string(APPEND SHATTER_SIMD_FLAGS " -ffp-contract=off")
endif()
# GCC 12's AVX-512 headers initialise a vector by itself (`__m256d __Y = __Y`,
# _mm256_undefined_pd), and Eigen's reductions inlined through them warn
# "'__Y' may be used uninitialized" or "is used uninitialized" (GCC bug
# 105593, fixed in GCC 13): some 700 lines of false positives per build. Those
# two warnings are off for these widths and compilers only; the baseline
# build, which CI also runs, keeps them for our code.
if(SHATTER_SIMD MATCHES "^(avx512|native)$" AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU"
   AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  string(APPEND SHATTER_SIMD_FLAGS " -Wno-maybe-uninitialized -Wno-uninitialized")
endif()
message(STATUS "shatter: SHATTER_SIMD=${SHATTER_SIMD} (${SHATTER_SIMD_FLAGS})")
