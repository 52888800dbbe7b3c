// Elementary functions over arrays, two lanes at a time where the C library has vector variants.
//
// exp_in_place uses glibc's libmvec (`_ZGVbN2v_exp`, the SSE variant of exp; libm's linker script
// links libmvec as needed) on x86-64 with glibc, and std::exp elsewhere. libmvec documents its
// vector exp to within 4 ulp (glibc manual, "Errors in Math Functions"; the SSE4 variant measured
// here is within 4.4e−16 relative of std::exp, tests/test_vector_math.cpp checks ≤ 4 ulp), far
// below the 1e−10 of a lobe's peak that per-material N_p keeps. Results depend only on the input
// values, not on where an array starts or how long it is, so a bake is the same for any thread
// count.
#pragma once

#include <span>

namespace hairlut {

/// x ← e^x for every element. Domain: any double (e^x underflows to 0 and overflows to +∞ as std::exp).
void exp_in_place(std::span<double> x);

}  // namespace hairlut
