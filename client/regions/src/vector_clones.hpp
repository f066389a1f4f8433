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
