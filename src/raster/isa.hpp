// Internal to the rasterizer (not installed): which SIMD kernel sets this build compiles.
//
// HEMILIGHT_RASTER_SSE2: the four-lane kernels (kernels_sse2.hpp), part of the x86-64 baseline.
// HEMILIGHT_RASTER_AVX2: the eight-lane kernels (kernels_avx2.hpp, leaf_avx.inl), compiled with
// target attributes (HEMILIGHT_TARGET_AVX2, HEMILIGHT_TARGET_AVX512) and picked at bind time from
// the CPU's features, so the library runs on any x86-64. Every kernel computes the scalar path's
// bits (the same float operations in the same order; the rasterizer's sources are compiled with
// -ffp-contract=off); tests/test_raster.cpp compares them bit for bit.
#pragma once

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define HEMILIGHT_RASTER_SSE2 1
#else
#define HEMILIGHT_RASTER_SSE2 0
#endif
// AVX2 kernels (eight texels per step), compiled for AVX2 with a target attribute and picked at
// run time, so the library itself still runs on any x86-64. GCC and Clang only. The eight-lane
// set-up is also compiled for AVX-512 (leaf_avx.inl), picked where the CPU has it.
#if HEMILIGHT_RASTER_SSE2 && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define HEMILIGHT_RASTER_AVX2 1
#define HEMILIGHT_TARGET_AVX2 __attribute__((target("avx2")))
#define HEMILIGHT_TARGET_AVX512 __attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq")))
#else
#define HEMILIGHT_RASTER_AVX2 0
#endif
