// g17 (io/g17.h) writes every double as std::to_chars at 17 significant digits does, byte for byte.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>

#include "harness/io/g17.h"

namespace tippe::test_g17 {
namespace {

std::string reference_text(double v) {
  char buf[64];
  return std::string(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17).ptr);
}

std::string g17_text(double v) {
  char buf[64];
  return std::string(buf, g17(buf, buf + sizeof buf, v));
}

TEST(G17, SpecialValuesAndLayouts) {
  for (double v : {0.0, -0.0, 1.0, -1.0, 0.5, 0.1, 1e-5, 1e-4, 9.9999999999999995e-5, 1e16, 1e17, 123456789012345678.0,
                   1e22, 1e-11, 1e-12, 1e43, 1e44, 5e-324, 1.7976931348623157e308, 2.5, 3.0, 0.001, 4.6850000000000005,
                   std::nan(""), -std::nan(""), HUGE_VAL, -HUGE_VAL, 99999999999999999.0, 0.99999999999999994})
    EXPECT_EQ(g17_text(v), reference_text(v)) << reference_text(v);
}

TEST(G17, RandomDoublesOfEveryExponent) {
  // Uniform bit patterns (every exponent alike, infinities, NaNs and subnormals among them),
  // then numbers of the trajectory's sizes (1e-40 .. 1e6, either sign: the ledger's small terms
  // go far below 1e-11), then short decimals of the same sizes, then dyadic numbers with up to
  // 53 significant bits (exact 17-digit ties among them, which go to to_chars), 500,000 each.
  std::mt19937_64 rng(29);
  int mismatches = 0;
  auto check = [&](double v) {
    if (g17_text(v) != reference_text(v) && ++mismatches <= 10) ADD_FAILURE() << reference_text(v) << " written " << g17_text(v);
  };
  for (int i = 0; i < 500000; ++i) {
    const std::uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    check(v);
  }
  std::uniform_real_distribution<double> mant(1.0, 10.0);
  std::uniform_int_distribution<int> exp10(-40, 6);
  for (int i = 0; i < 500000; ++i) check((i % 2 ? -1 : 1) * mant(rng) * std::pow(10.0, exp10(rng)));
  std::uniform_int_distribution<std::int64_t> digits(1, 999999999);
  for (int i = 0; i < 500000; ++i) check(static_cast<double>(digits(rng)) * std::pow(10.0, exp10(rng)));
  std::uniform_int_distribution<int> shift(0, 52), exp2(-150, 60);
  for (int i = 0; i < 500000; ++i) check((i % 2 ? -1 : 1) * std::ldexp(static_cast<double>(rng() >> (11 + shift(rng))), exp2(rng)));
  EXPECT_EQ(mismatches, 0);
}

}  // namespace
}  // namespace tippe
