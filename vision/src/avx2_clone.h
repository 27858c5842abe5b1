#pragma once
// EPICHEAD_AVX2_CLONE: a function also built for AVX2 and picked at load time where the CPU has
// it (the build targets x86-64-v2). For element-wise loops: twice the lanes, the same
// operations per lane (no FMA: the build sets -ffp-contract=off), so the same values.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define EPICHEAD_AVX2_CLONE __attribute__((target_clones("avx2", "default")))
#else
#define EPICHEAD_AVX2_CLONE
#endif
