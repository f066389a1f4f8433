#pragma once
// How many of n samples may lie outside their 99% region when the true rate is 1%: the
// count that a 1% rate exceeds in at most 1% of sets of n (binomial). A bar of 1% of n
// would fail an exact covariance in about half the sets (its expected count is 0.01 n).
#include <cmath>

namespace covtrack::test {

inline int most_outside_at_one_percent(int n) {
  double p_k = std::pow(0.99, n), below = 0;  // P(X = k); P(X <= k) once p_k is added
  for (int k = 0; k <= n; ++k) {
    below += p_k;
    if (1 - below <= 0.01) return k;
    p_k *= (n - k) / (k + 1.0) * (0.01 / 0.99);
  }
  return n;
}

}  // namespace covtrack::test
