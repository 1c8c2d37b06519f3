// Vectors of doubles for the dispatched kernels (cpu_dispatch.h): GCC's vector extension, whose
// elementwise operations are IEEE arithmetic lane by lane, lowered to whatever registers the
// variant being compiled has. A kernel written on VectorOf<W> therefore computes, in each lane,
// exactly what the scalar code of the same expressions computes (the project compiles with
// -ffp-contract=off: no fused multiply-adds), whatever W and whatever instruction set.
//
// These helpers take and return vectors wider than the baseline ABI passes in registers, and
// GCC notes (-Wpsabi) that such a call's ABI depends on the instruction set. They are only ever
// force-inlined into a variant function whose own arguments are pointers and scalars, so no such
// call exists; the note is silenced for the files that include this header (kernel files only).
#pragma once

#include <cstring>

#pragma GCC diagnostic ignored "-Wpsabi"

namespace lrcal::lanes {

template <int W>
struct VectorOf;
template <>
struct VectorOf<2> {
  using type = double __attribute__((vector_size(16)));
};
template <>
struct VectorOf<4> {
  using type = double __attribute__((vector_size(32)));
};
template <>
struct VectorOf<8> {
  using type = double __attribute__((vector_size(64)));
};

/// The number of doubles in V.
template <typename V>
inline constexpr int kWidth = static_cast<int>(sizeof(V) / sizeof(double));

/// W doubles from p (unaligned).
template <typename V>
[[gnu::always_inline]] inline V Load(const double* p) {
  V v = {};
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// The first `valid` lanes of v to p (unaligned; all of them in one store when valid = W).
template <typename V>
[[gnu::always_inline]] inline void Store(double* p, const V& v, int valid = kWidth<V>) {
  if (valid == kWidth<V>)
    std::memcpy(p, &v, sizeof v);
  else
    for (int k = 0; k < valid; ++k) p[k] = v[k];
}

/// Every lane x (a negative zero stays one, as the scalar it stands for).
template <typename V>
[[gnu::always_inline]] inline V All(double x) {
  V v = {};
  for (int k = 0; k < kWidth<V>; ++k) v[k] = x;
  return v;
}

}  // namespace lrcal::lanes
