// Portable short vectors for the element kernels (GCC/Clang vector extensions): kLanes doubles per vector, 4 when
// the target has AVX (e.g. -march=native, SHELLDYN_NATIVE), else SSE2's 2. Lane-wise IEEE arithmetic; used where
// GCC does not vectorize plain loops by itself (arrays over the nine nodes, the packed K_bs product).
#pragma once

#include <cstring>

namespace shelldyn::simd {

#if defined(__AVX__)
constexpr int kLanes = 4;
#else
constexpr int kLanes = 2;
#endif
typedef double V __attribute__((vector_size(8 * kLanes)));

inline V splat(double a) {
  V v;
  for (int k = 0; k < kLanes; ++k) v[k] = a;
  return v;
}
// Unaligned load and store of kLanes doubles.
inline V load(const double* p) {
  V v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store(double* p, V v) { std::memcpy(p, &v, sizeof v); }

}  // namespace shelldyn::simd
