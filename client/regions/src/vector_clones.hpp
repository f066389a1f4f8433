#pragma once
// Hot loops over fixed-size blocks are written so that the compiler vectorises them. Built
// for the baseline x86-64 they get 2 doubles per instruction; this attribute adds clones
// for x86-64-v3 (AVX2, FMA: 4 doubles) and x86-64-v4 (AVX-512: 8 doubles, a block of 8 in
// one instruction), the one used chosen at load time by the CPU that runs it, so the binary
// stays portable. Elsewhere, or built with -DCOVTRACK_NO_VECTOR_CLONES (to test the
// baseline code on a machine that has AVX2), it is empty and the loops stay plain.
//
// A cloned function is not inlined into its caller, so the compiler must see for itself
// that the loop's stores cannot change what it reads: keep the arrays it reads and writes
// in one struct, or in local copies. Arrays passed in separately make it give up (more
// than ten overlap checks), silently: check a new loop with -fopt-info-vec-all.
//
// vector_clones_have_avx2() says whether the clones chosen run with AVX2 or more (the
// x86-64-v3 or v4 clone), for code that pays off only then (and a baseline path to take
// otherwise).
#include <cstdint>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(COVTRACK_NO_VECTOR_CLONES)
#define COVTRACK_VECTOR_CLONES __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
inline bool vector_clones_have_avx2() {
  static const bool avx2 = __builtin_cpu_supports("x86-64-v3");
  return avx2;
}
#else
#define COVTRACK_VECTOR_CLONES
inline bool vector_clones_have_avx2() { return false; }
#endif

namespace covtrack::client {
// GCC vector types, for loops the vectoriser leaves scalar: 2 doubles (a plain x86-64
// register), 4 (an AVX2 register), and the mask a comparison of 4 gives. GCC 12 splits
// comparisons of vectors wider than the clone's registers into scalars, so code that
// compares picks its width by vector_clones_have_avx2().
using DoubleLanes2 = double __attribute__((vector_size(2 * sizeof(double))));
using DoubleLanes4 = double __attribute__((vector_size(4 * sizeof(double))));
using MaskLanes4 = std::int64_t __attribute__((vector_size(4 * sizeof(std::int64_t))));
}  // namespace covtrack::client
