#include "hairlut/util/vector_math.hpp"

#include <cmath>

#if defined(__x86_64__) && defined(__GLIBC__) && defined(__SSE2__)
#include <emmintrin.h>
extern "C" __m128d _ZGVbN2v_exp(__m128d);  // glibc libmvec, GLIBC_2.22
#define HAIRLUT_LIBMVEC 1
#endif

namespace hairlut {

void exp_in_place(std::span<double> x) {
  std::size_t i = 0;
#ifdef HAIRLUT_LIBMVEC
  // Pairs through the vector variant; a last odd element as a pair with a copy of itself, so that
  // every element goes through the same function whatever the array's length.
  for (; i + 2 <= x.size(); i += 2) _mm_storeu_pd(x.data() + i, _ZGVbN2v_exp(_mm_loadu_pd(x.data() + i)));
  if (i < x.size()) {
    const __m128d v = _ZGVbN2v_exp(_mm_set1_pd(x[i]));
    x[i] = _mm_cvtsd_f64(v);
    ++i;
  }
#endif
  for (; i < x.size(); ++i) x[i] = std::exp(x[i]);
}

}  // namespace hairlut
