#pragma once
// How many of n samples may lie outside their region of probability 1 - rate when the
// true rate is `rate`: the count that rate exceeds in at most 1% of sets of n (binomial).
// A bar of rate * n would fail an exact covariance in about half the sets (its expected
// count is rate * n).
#include <cmath>

namespace covtrack::test {

inline int most_outside(int n, double rate) {
  double p_k = std::pow(1 - rate, n), below = 0;  // P(X = k); P(X <= k) once p_k is added
  for (int k = 0; k <= n; ++k) {
    below += p_k;
    if (1 - below <= 0.01) return k;
    p_k *= (n - k) / (k + 1.0) * (rate / (1 - rate));
  }
  return n;
}

// Outside the 99% regions, the most of n.
inline int most_outside_at_one_percent(int n) { return most_outside(n, 0.01); }

}  // namespace covtrack::test
