// A double as printf's "%.17g" writes it (std::to_chars, general, precision 17), byte for byte, with a fast path for the trajectory's rows.
#pragma once

#include <charconv>
#include <cstdint>
#include <cstring>
#include <system_error>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace tippe {

namespace g17_detail {

inline constexpr char kPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

// n < 10^8 as its 8 decimal digits, one a byte, the first in the lowest byte (add '0' to each
// for the text on a little-endian machine): two 4-digit halves in the word's 32-bit lanes, each
// split into 2-digit quarters in 16-bit lanes (/ 100 as * 10486 >> 20, exact below 10^4), each
// of those into digits in bytes (/ 10 as * 103 >> 10, exact below 179); no lane's product reaches
// the next one. Checked for every n.
inline std::uint64_t digit_bytes8(std::uint32_t n) {
  const std::uint64_t hi = n / 10000U, lo = n - hi * 10000U;
  std::uint64_t v = hi | (lo << 32);
  const std::uint64_t q = ((v * 10486U) >> 20) & 0x0000007F0000007FULL;
  v = q | ((v - q * 100U) << 16);
  const std::uint64_t t = ((v * 103U) >> 10) & 0x000F000F000F000FULL;
  return t | ((v - t * 10U) << 8);
}

#if defined(__SSE2__)
// n < 10^8 as its 8 decimal digits in 16-bit lanes, the first in lane 0 (SSE2, part of x86-64):
// n / 10^4 and n % 10^4 by a multiplication, each broadcast to four lanes and divided by 10^3,
// 10^2, 10 and 1 by multiply-high with a reciprocal and a shift, then each quotient less ten
// times its predecessor. Checked for every n.
inline __m128i digit_lanes8(std::uint32_t n) {
  const __m128i v = _mm_cvtsi32_si128(static_cast<int>(n));
  const __m128i hi = _mm_srli_epi64(_mm_mul_epu32(v, _mm_set1_epi32(static_cast<int>(0xd1b71759U))), 45);
  const __m128i lo = _mm_sub_epi32(v, _mm_mul_epu32(hi, _mm_set1_epi32(10000)));
  const __m128i v1 = _mm_slli_epi64(_mm_unpacklo_epi16(hi, lo), 2);
  const __m128i v2 = _mm_unpacklo_epi32(_mm_unpacklo_epi16(v1, v1), _mm_unpacklo_epi16(v1, v1));
  const __m128i v3 = _mm_mulhi_epu16(v2, _mm_setr_epi16(8389, 5243, 13108, -32768, 8389, 5243, 13108, -32768));
  const __m128i v4 = _mm_mulhi_epu16(v3, _mm_setr_epi16(1 << 7, 1 << 11, 1 << 13, -32768, 1 << 7, 1 << 11, 1 << 13, -32768));
  return _mm_sub_epi16(v4, _mm_slli_epi64(_mm_mullo_epi16(v4, _mm_set1_epi16(10)), 16));
}
#endif

#if defined(__SIZEOF_INT128__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
__extension__ typedef unsigned __int128 u128;

// The decimal powers the fast path multiplies by: 10^k for k = kMinPower..kMaxPower, each as its
// 128 leading bits P (2^127 <= P < 2^128, truncated, so never above the power) and a binary
// exponent q with 10^k ~ P 2^q. kMinPower: numbers below 1e44 (10^-27's reciprocal needs a divisor
// below 2^90 for the long division below); kMaxPower: every normal double (16 + 308 + 1).
inline constexpr int kMinPower = -27;
inline constexpr int kMaxPower = 325;

struct Power {
  std::uint64_t hi, lo;
  int q;
};

struct PowerTable {
  Power p[kMaxPower - kMinPower + 1];
};

// Built at compile time: 10^k for k >= 0 as an exact integer of 64-bit limbs (10^325 < 2^1080,
// 17 limbs), its leading 128 bits; 10^-j as 2^(127 + b) / 10^j by long division (10^j < 2^b).
constexpr PowerTable make_power_table() {
  PowerTable t{};
  std::uint64_t limb[18] = {1};
  int limbs = 1;
  for (int k = 0; k <= kMaxPower; ++k) {
    if (k > 0) {
      std::uint64_t carry = 0;
      for (int i = 0; i < limbs; ++i) {
        const u128 v = static_cast<u128>(limb[i]) * 10 + carry;
        limb[i] = static_cast<std::uint64_t>(v);
        carry = static_cast<std::uint64_t>(v >> 64);
      }
      if (carry) limb[limbs++] = carry;
    }
    int top = 63;
    while (!((limb[limbs - 1] >> top) & 1)) --top;
    const int bits = 64 * (limbs - 1) + top + 1;  // 10^k < 2^bits
    // The 128 bits below and at the leading one (zeros beyond the number's own bits).
    std::uint64_t w[2] = {0, 0};
    for (int i = 0; i < 128; ++i) {
      const int b = bits - 1 - i;
      const std::uint64_t bit = b >= 0 ? (limb[b / 64] >> (b % 64)) & 1 : 0;
      w[i / 64] |= bit << (63 - i % 64);
    }
    t.p[k - kMinPower] = Power{w[0], w[1], bits - 128};
  }
  for (int j = 1; j <= -kMinPower; ++j) {
    u128 d = 1;
    for (int i = 0; i < j; ++i) d *= 10;
    int b = 0;
    while ((d >> b) != 0) ++b;
    // floor(2^(127 + b) / d): between 2^127 and 2^128, as d is between 2^(b-1) and 2^b.
    u128 r = 1, quo = 0;
    for (int i = 0; i < 127 + b; ++i) {
      r <<= 1;
      quo <<= 1;
      if (r >= d) {
        r -= d;
        quo |= 1;
      }
    }
    t.p[-j - kMinPower] = Power{static_cast<std::uint64_t>(quo >> 64), static_cast<std::uint64_t>(quo), -(127 + b)};
  }
  return t;
}

inline constexpr PowerTable kPowers = make_power_table();

// The index of a nonzero word's highest nonzero byte.
inline int top_byte(std::uint64_t w) { return (63 - __builtin_clzll(w)) / 8; }

// The 17 significant digits of a > 0 (given by its bits) rounded to nearest, and the decimal
// exponent X of the rounded value (a ~ N 10^(X-16), 10^16 <= N < 10^17); false where the fast
// path cannot vouch for the rounding (see g17).
inline bool digits17(std::uint64_t bits, std::uint64_t& n, int& x) {
  const int biased = static_cast<int>(bits >> 52) & 0x7ff;
  if (biased == 0 || biased == 0x7ff) return false;  // subnormal, infinite or NaN: to_chars
  // a = m 2^e, 2^52 <= m < 2^53; a lies in [2^(e2-1), 2^e2).
  const std::uint64_t m = (bits & ((std::uint64_t{1} << 52) - 1)) | (std::uint64_t{1} << 52);
  const int e = biased - 1075, e2 = biased - 1022;
  // floor(log10(2^(e2-1))) (78913 / 2^18 just under log10(2), exact for |e2| < 1650; the shift
  // of a negative product floors): floor(log10(a)) or one below.
  x = ((e2 - 1) * 78913) >> 18;
  for (int pass = 0; pass < 2; ++pass) {
    const int k = 16 - x;
    if (k < kMinPower || k > kMaxPower) return false;
    const Power& pw = kPowers.p[k - kMinPower];
    // a 10^k ~ m P 2^(e+q): the product's bits above its low 64 (hi:lo), and the binary point
    // r bits up from their bottom: 56 <= r <= 63 for a 10^k in [1e16, 1e18) (m P is in
    // [2^179, 2^181)), so the whole part is hi's low bits over lo's high ones.
    const u128 top = static_cast<u128>(m) * pw.hi + ((static_cast<u128>(m) * pw.lo) >> 64);
    const int r = -(e + pw.q) - 64;
    if (r < 56 || r > 63) return false;  // not expected
    const auto hi = static_cast<std::uint64_t>(top >> 64), lo = static_cast<std::uint64_t>(top);
    const std::uint64_t whole = (hi << (64 - r)) | (lo >> r);
    if (whole >= 100000000000000000ULL) {
      ++x;
      continue;
    }
    if (whole < 10000000000000000ULL) return false;  // the estimate is never high; not expected
    // whole + frac / 2^64 is below a 10^k by less than 2^-55 (2^9 in frac's units: the product's
    // dropped low bits, under 2^-r, and P's truncation, under a 10^k 2^-127). Away from a half
    // by more than that, the rounding to nearest of the exact product is that of this one; near
    // a half (a tie or close to one) it is left to to_chars.
    const std::uint64_t frac = lo << (64 - r);
    constexpr std::uint64_t half = std::uint64_t{1} << 63, margin = std::uint64_t{1} << 12;
    if (frac >= half - margin && frac <= half + margin) return false;
    n = whole + (frac > half ? 1 : 0);
    if (n == 100000000000000000ULL) {
      n = 10000000000000000ULL;
      ++x;
    }
    return true;
  }
  return false;
}
#else
// No 128-bit product (MSVC) or a big-endian machine: every number goes to to_chars.
inline bool digits17(std::uint64_t, std::uint64_t&, int&) { return false; }
inline int top_byte(std::uint64_t w) {
  int b = 0;
  while (w >>= 8) ++b;
  return b;
}
#endif

}  // namespace g17_detail

// Writes v into [p, end) as std::to_chars(p, end, v, std::chars_format::general, 17) does (the
// same bytes: "%.17g" in the C locale) and returns the end of what it wrote; end - p must be
// at least 40 (the fast path writes whole blocks of digits and moves the end back). The
// trajectory writes 33 numbers per sample this way: libstdc++'s to_chars at a given precision
// takes ~600 instructions a number; this path takes about a sixth of that for every normal
// number below 1e44 and zeros, and hands the rest, infinities and NaNs (and the few numbers
// whose digits beyond the 17th are within 2^-52 of a rounding tie) to to_chars.
inline char* g17(char* p, char* end, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  const bool negative = (bits >> 63) != 0;
  if ((bits << 1) == 0) {  // "0" or "-0"
    if (negative) *p++ = '-';
    *p++ = '0';
    return p;
  }
  std::uint64_t n = 0;
  int x = 0;
  if (!g17_detail::digits17(bits & ~(std::uint64_t{1} << 63), n, x))
    return std::to_chars(p, end, v, std::chars_format::general, 17).ptr;
  // The 17 digits: the first, then the other 16 as text in `tail`; `last`, the last digit kept
  // (%g drops trailing zeros), from the highest nonzero one.
  const std::uint64_t upper = n / 100000000U;  // 9 digits
  const char first = static_cast<char>('0' + upper / 100000000U);
  const auto mid8 = static_cast<std::uint32_t>(upper % 100000000U), low8 = static_cast<std::uint32_t>(n % 100000000U);
  char tail[16];
#if defined(__SSE2__)
  const __m128i digits = _mm_packus_epi16(g17_detail::digit_lanes8(mid8), g17_detail::digit_lanes8(low8));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(tail), _mm_add_epi8(digits, _mm_set1_epi8('0')));
  const unsigned nonzero = ~static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(digits, _mm_setzero_si128()))) & 0xffffU;
  const int last = nonzero ? 1 + (31 - __builtin_clz(nonzero)) : 0;
#else
  const std::uint64_t b1 = g17_detail::digit_bytes8(mid8), b2 = g17_detail::digit_bytes8(low8);
  const std::uint64_t zeros = 0x3030303030303030ULL;  // '0' in every byte
  const std::uint64_t t1 = b1 | zeros, t2 = b2 | zeros;
  std::memcpy(tail, &t1, 8);
  std::memcpy(tail + 8, &t2, 8);
  const int last = b2 ? 9 + g17_detail::top_byte(b2) : b1 ? 1 + g17_detail::top_byte(b1) : 0;
#endif
  // Each layout writes the 17 digits whole and moves p to the end of the digits kept.
  if (negative) *p++ = '-';
  if (x < -4 || x >= 17) {  // d.ddde-XX
    p[0] = first;
    p[1] = '.';
    std::memcpy(p + 2, tail, 16);
    p += last > 0 ? last + 2 : 1;
    *p++ = 'e';
    *p++ = x < 0 ? '-' : '+';
    const int ax = x < 0 ? -x : x;
    if (ax >= 100) *p++ = static_cast<char>('0' + ax / 100);
    std::memcpy(p, g17_detail::kPairs + 2 * (ax % 100), 2);
    p += 2;
  } else if (x >= 0) {  // the digits up to x, '.', the rest
    char d[40];
    d[0] = first;
    std::memcpy(d + 1, tail, 16);
    std::memset(d + 17, '0', 23);  // what the second block copy reads beyond the digits
    std::memcpy(p, d, 17);
    p[x + 1] = '.';
    std::memcpy(p + x + 2, d + x + 1, 16);
    p += last > x ? last + 2 : x + 1;
  } else {  // "0." then -x-1 zeros, then the digits
    std::memcpy(p, "0.000", 5);
    p += 1 - x;
    p[0] = first;
    std::memcpy(p + 1, tail, 16);
    p += last + 1;
  }
  return p;
}

}  // namespace tippe
