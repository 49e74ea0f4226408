// A table-once binomial coefficient for Boost.Odeint's Bulirsch-Stoer dense output (bit-identical to Boost 1.74's), which otherwise dominates the reference's cost.
#pragma once

// Declared before binomial.hpp, whose own float specialization instantiates the double one:
// include this header before any Boost.Math or Boost.Odeint header.
#include <boost/math/special_functions/math_fwd.hpp>

namespace boost {
namespace math {
template <>
inline double binomial_coefficient<double, policies::policy<>>(unsigned n, unsigned k, const policies::policy<>& pol);
}  // namespace math
}  // namespace boost

#include <boost/math/special_functions/binomial.hpp>
#include <boost/math/special_functions/factorials.hpp>

#include <array>
#include <cmath>

namespace boost {
namespace math {

// Why: bulirsch_stoer_dense_out calls binomial_coefficient<double> for every step's dense
// output, and Boost 1.74 builds it from unchecked_factorial<long double>, whose table is a
// constexpr *local* array: every call copies 2.6 KB onto the stack (3 calls per coefficient).
// Measured on the toy top: 14-23 % of a whole reference run. This is Boost's own formula
// (n! / (n-k)! / k! in double, each factorial rounded from long double), with the table built
// once, so every result is the same double as Boost's. Beyond the table (n > 170, never reached:
// odeint's n is at most twice its extrapolation order) it takes Boost's long double path. Boost specializes the same function for float in the same way.
template <>
inline double binomial_coefficient<double, policies::policy<>>(unsigned n, unsigned k, const policies::policy<>& pol) {
  static const std::array<double, max_factorial<double>::value + 1> kFactorial = [] {
    std::array<double, max_factorial<double>::value + 1> f{};
    for (unsigned i = 0; i < f.size(); ++i) f[i] = static_cast<double>(unchecked_factorial<long double>(i));
    return f;
  }();
  if (k > n || n > max_factorial<double>::value)
    return static_cast<double>(binomial_coefficient<long double>(n, k, pol));
  if (k == 0 || k == n) return 1.0;
  if (k == 1 || k == n - 1) return static_cast<double>(n);
  double result = kFactorial[n];
  result /= kFactorial[n - k];
  result /= kFactorial[k];
  return std::ceil(result - 0.5f);  // Boost's rounding to the nearest integer
}

}  // namespace math
}  // namespace boost
