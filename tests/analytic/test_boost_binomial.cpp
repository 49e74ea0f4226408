// The table-once binomial coefficient (analytic/boost_binomial.h) gives exactly the doubles of Boost's own formula.
#include "analytic/boost_binomial.h"  // first, as in the reference model

#include <gtest/gtest.h>

#include <cmath>

namespace test_boost_binomial {

// Boost 1.74's formula for binomial_coefficient<double>, written out: n! / (n-k)! / k! in double
// from long double factorials, rounded to the nearest integer. Equality is exact (==): the
// replacement exists only to be bit-identical and faster.
double boost_formula(unsigned n, unsigned k) {
  if (k == 0 || k == n) return 1.0;
  if (k == 1 || k == n - 1) return static_cast<double>(n);
  double r = static_cast<double>(boost::math::unchecked_factorial<long double>(n));
  r /= static_cast<double>(boost::math::unchecked_factorial<long double>(n - k));
  r /= static_cast<double>(boost::math::unchecked_factorial<long double>(k));
  return std::ceil(r - 0.5f);
}

TEST(BoostBinomial, SameDoublesAsBoostsFormula) {
  for (unsigned n = 0; n <= 170; ++n)
    for (unsigned k = 0; k <= n; ++k)
      ASSERT_EQ(boost::math::binomial_coefficient<double>(n, k), boost_formula(n, k)) << n << " choose " << k;
}

// Integers below 2^53 are exact: the values odeint uses (n up to twice its order) are the true ones.
TEST(BoostBinomial, SmallCoefficientsAreExact) {
  EXPECT_EQ(boost::math::binomial_coefficient<double>(16, 8), 12870.0);
  EXPECT_EQ(boost::math::binomial_coefficient<double>(30, 15), 155117520.0);
  EXPECT_EQ(boost::math::binomial_coefficient<double>(5, 2), 10.0);
}

}  // namespace test_boost_binomial
