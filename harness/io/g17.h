// A double as printf's "%.17g" writes it (std::to_chars, general, precision 17), byte for byte, with a fast path for the trajectory's rows.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <system_error>

namespace tippe {

namespace g17_detail {

// 10^k for k = 0..27, each exact in x87 extended precision (5^27 < 2^64).
inline const long double* powers_of_ten() {
  static const auto table = [] {
    struct T {
      long double v[28];
    } t{};
    long double p = 1.0L;
    for (int k = 0; k < 28; ++k, p *= 10.0L) t.v[k] = p;
    return t;
  }();
  return table.v;
}

// The 17 significant digits of a > 0 rounded to nearest, and the decimal exponent X of the
// rounded value (a ~ N 10^(X-16), 10^16 <= N < 10^17); false where the fast path cannot vouch
// for the rounding (see g17).
inline bool digits17(double a, std::uint64_t& n, int& x) {
  // The error bounds below need x87 extended precision (a 64-bit mantissa, as on x86-64): where
  // long double is narrower (a plain double on ARM's and MSVC's ABIs) the products are no longer
  // within 2^-64, and every number goes to to_chars.
  if constexpr (std::numeric_limits<long double>::digits < 64) return false;
  // a = f 2^e2 with 0.5 <= f < 1, from the biased exponent (a is normal: a subnormal, below
  // 2.2e-308, has k > 54 and is handed to to_chars below).
  std::uint64_t bits;
  std::memcpy(&bits, &a, sizeof bits);
  const int e2 = static_cast<int>((bits >> 52) & 0x7ff) - 1022;
  x = static_cast<int>(std::floor((e2 - 1) * 0.30102999566398120));  // floor(log10(a)), or one below
  for (int pass = 0; pass < 2; ++pass) {
    const int k = 16 - x;
    if (k < -27 || k > 54) return false;
    // One exact power (10^27 at most) or, for numbers down to 1e-38 (the ledger's small terms),
    // two: one rounding or two, each within 2^-64 relative.
    const long double s = k > 27    ? static_cast<long double>(a) * powers_of_ten()[27] * powers_of_ten()[k - 27]
                          : k >= 0 ? static_cast<long double>(a) * powers_of_ten()[k]
                                   : static_cast<long double>(a) / powers_of_ten()[-k];
    if (s >= 1e17L) {
      ++x;
      continue;
    }
    if (s < 1e16L) return false;  // the estimate is never high; not expected
    // s is a 10^k rounded once or twice: within 2^-63 relative, 0.016 below 2^57 > 1e17. Its
    // fraction is exact; away from 1/2 by more than that error, the nearest integer of the
    // exact product is that of s. Near 1/2 (a tie or close to one) the exact rounding is left
    // to to_chars.
    const long double fl = std::floor(s);
    const long double frac = s - fl;
    if (frac > 0.48L && frac < 0.52L) return false;
    n = static_cast<std::uint64_t>(fl) + (frac >= 0.52L ? 1 : 0);
    if (n == 100000000000000000ULL) {
      n = 10000000000000000ULL;
      ++x;
    }
    return true;
  }
  return false;
}

}  // namespace g17_detail

// Writes v into [p, end) as std::to_chars(p, end, v, std::chars_format::general, 17) does (the
// same bytes: "%.17g" in the C locale) and returns the end of what it wrote; end - p must be
// at least 32. The trajectory writes 33 numbers per sample this way: libstdc++'s to_chars at a
// given precision takes ~600 instructions a number; this path takes about a tenth of that for
// numbers between 1e-38 and 1e43 and zeros, and hands the rest, infinities and NaNs (and the few
// numbers whose 18th digit is close to a tie) to to_chars.
inline char* g17(char* p, char* end, double v) {
  if (v == 0.0) {  // "0" or "-0"
    if (std::signbit(v)) *p++ = '-';
    *p++ = '0';
    return p;
  }
  const double a = std::fabs(v);
  std::uint64_t n = 0;
  int x = 0;
  if (!(std::isfinite(v) && g17_detail::digits17(a, n, x)))
    return std::to_chars(p, end, v, std::chars_format::general, 17).ptr;
  // The digits two at a time from 32-bit halves (9 and 8 digits).
  static constexpr char kPairs[] =
      "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
      "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
      "8081828384858687888990919293949596979899";
  char d[17];
  std::uint32_t lo = static_cast<std::uint32_t>(n % 100000000U), hi = static_cast<std::uint32_t>(n / 100000000U);
  for (int i = 15; i >= 9; i -= 2, lo /= 100) {
    d[i] = kPairs[2 * (lo % 100)];
    d[i + 1] = kPairs[2 * (lo % 100) + 1];
  }
  for (int i = 7; i >= 1; i -= 2, hi /= 100) {
    d[i] = kPairs[2 * (hi % 100)];
    d[i + 1] = kPairs[2 * (hi % 100) + 1];
  }
  d[0] = static_cast<char>('0' + hi);
  int last = 16;  // the last digit kept: %g drops trailing zeros
  while (last > 0 && d[last] == '0') --last;
  if (std::signbit(v)) *p++ = '-';
  if (x < -4 || x >= 17) {
    *p++ = d[0];
    if (last > 0) {
      *p++ = '.';
      for (int i = 1; i <= last; ++i) *p++ = d[i];
    }
    *p++ = 'e';
    *p++ = x < 0 ? '-' : '+';
    const int ax = x < 0 ? -x : x;
    if (ax >= 100) *p++ = static_cast<char>('0' + ax / 100);
    *p++ = static_cast<char>('0' + ax / 10 % 10);
    *p++ = static_cast<char>('0' + ax % 10);
  } else if (x >= 0) {
    for (int i = 0; i <= x; ++i) *p++ = d[i];
    if (last > x) {
      *p++ = '.';
      for (int i = x + 1; i <= last; ++i) *p++ = d[i];
    }
  } else {
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -x - 1; ++i) *p++ = '0';
    for (int i = 0; i <= last; ++i) *p++ = d[i];
  }
  return p;
}

}  // namespace tippe
