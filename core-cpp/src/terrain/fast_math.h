// Fast, seeded random numbers and approximations for the particle filter's inner loops.
// Private to the terrain module. Accuracy is stated per function; tests cover them.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace pdnav::terrain::detail {

/// SplitMix64 (Steele, Lea, Flood 2014): expands one 64-bit seed into generator states.
inline std::uint64_t splitmix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

/// xoshiro256+ (Blackman & Vigna 2018): fast 64-bit generator for floating-point use; its
/// weak low bits are never used alone here (uniforms take the high bits).
class Xoshiro256Plus {
 public:
  explicit Xoshiro256Plus(std::uint64_t seed = 1) { reseed(seed); }
  void reseed(std::uint64_t seed) {
    std::uint64_t x = seed;
    for (auto& v : s_) v = splitmix64(x);
  }
  std::uint64_t next() {
    const std::uint64_t result = s_[0] + s_[3];
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = (s_[3] << 45) | (s_[3] >> 19);
    return result;
  }
  /// Uniform in [0, 1) from the top 24 bits.
  float uniform_f() { return static_cast<float>(next() >> 40) * 0x1.0p-24f; }
  /// Uniform in (0, 1] from the top 53 bits (never 0: safe for log).
  double uniform_open0() { return (static_cast<double>(next() >> 11) + 1.0) * 0x1.0p-53; }

 private:
  std::uint64_t s_[4];
};

/// kLanes independent xoshiro128+ streams (Blackman & Vigna 2018, the 32-bit member of the
/// family meant for floating-point use), state as structure of arrays: one loop over the lanes
/// advances all of them in SIMD registers (adds, shifts and xors only; SSE2 has no 32-bit
/// multiply, so the ** and ++ scramblers would not vectorise). Each lane is seeded from the
/// SplitMix64 sequence of one seed: deterministic for a seed, independent of the lane count
/// used afterwards. The lowest bits of a + scrambler are weak; they only ever enter Irwin-Hall
/// sums here, where they weigh less than 2^-12.
template <std::size_t kLanes>
class LaneXoshiro128Plus {
 public:
  explicit LaneXoshiro128Plus(std::uint64_t seed = 1) { reseed(seed); }
  void reseed(std::uint64_t seed) {
    std::uint64_t x = seed;
    for (std::size_t l = 0; l < kLanes; ++l) {
      const std::uint64_t a = splitmix64(x), b = splitmix64(x);
      s0_[l] = static_cast<std::uint32_t>(a);
      s1_[l] = static_cast<std::uint32_t>(a >> 32);
      s2_[l] = static_cast<std::uint32_t>(b);
      s3_[l] = static_cast<std::uint32_t>(b >> 32) | 1u;  // never the all-zero state
    }
  }
  /// Four consecutive draws of every lane: o0[l] .. o3[l] (each array kLanes words).
  void fill4(std::uint32_t* __restrict o0, std::uint32_t* __restrict o1, std::uint32_t* __restrict o2,
             std::uint32_t* __restrict o3) {
    for (std::size_t l = 0; l < kLanes; ++l) {
      std::uint32_t a = s0_[l], b = s1_[l], c = s2_[l], d = s3_[l];
      o0[l] = next(a, b, c, d);
      o1[l] = next(a, b, c, d);
      o2[l] = next(a, b, c, d);
      o3[l] = next(a, b, c, d);
      s0_[l] = a;
      s1_[l] = b;
      s2_[l] = c;
      s3_[l] = d;
    }
  }

 private:
  static std::uint32_t next(std::uint32_t& s0, std::uint32_t& s1, std::uint32_t& s2, std::uint32_t& s3) {
    const std::uint32_t result = s0 + s3;
    const std::uint32_t t = s1 << 9;
    s2 ^= s0;
    s3 ^= s1;
    s1 ^= s2;
    s0 ^= s3;
    s2 ^= t;
    s3 = (s3 << 11) | (s3 >> 21);
    return result;
  }
  alignas(64) std::uint32_t s0_[kLanes];
  alignas(64) std::uint32_t s1_[kLanes];
  alignas(64) std::uint32_t s2_[kLanes];
  alignas(64) std::uint32_t s3_[kLanes];
};

/// Sum of the two 16-bit halves of a 32-bit draw, as an integer in [0, 2 x 65535]: two
/// uniforms of an Irwin-Hall sum at once (vectorises: and, shift, add).
inline std::int32_t halves_sum(std::uint32_t r) {
  return static_cast<std::int32_t>((r & 0xFFFFu) + (r >> 16));
}

/// Standard normal approximation from two 32-bit draws: the same Irwin-Hall(4) of 16-bit
/// uniforms as normal_from_bits, branch-free and vectorisable.
inline float normal_from_words(std::uint32_t a, std::uint32_t b) {
  const float sum = static_cast<float>(halves_sum(a) + halves_sum(b)) * (1.0f / 65536.0f);
  return (sum - 2.0f + 2.0f / 65536.0f) * 1.7320508f;
}

/// Standard normal approximation from one 64-bit draw: Irwin-Hall sum of four 16-bit
/// uniforms, centred and scaled to unit variance (support +-3.46 sigma, excess kurtosis -0.3).
/// Used for process noise only, where the truncated tails are harmless.
inline float normal_from_bits(std::uint64_t r) {
  const auto a = static_cast<std::uint32_t>(r & 0xFFFFu);
  const auto b = static_cast<std::uint32_t>((r >> 16) & 0xFFFFu);
  const auto c = static_cast<std::uint32_t>((r >> 32) & 0xFFFFu);
  const auto d = static_cast<std::uint32_t>(r >> 48);
  const float sum = static_cast<float>(a + b + c + d) * (1.0f / 65536.0f);  // mean 2, var 1/3
  return (sum - 2.0f + 2.0f / 65536.0f) * 1.7320508f;
}

/// Round to nearest (ties to even) for |x| < 2^22 without a libm call (needs IEEE
/// arithmetic: the project never builds with -ffast-math).
inline float round_nearest(float x) {
  constexpr float kMagic = 12582912.0f;  // 1.5 * 2^23
  return (x + kMagic) - kMagic;
}

/// 2^f on [-0.5, 0.5]: degree-6 polynomial (coefficients ln2^n / n!, minimax-adjusted), for
/// float and for the 4-lane Float4 (the same operations in the same order).
template <typename T>
inline T exp2_poly(T f) {
  T p = f * 1.5403530e-4f + 1.3333558e-3f;
  p = p * f + 9.6181291e-3f;
  p = p * f + 5.5504109e-2f;
  p = p * f + 2.4022651e-1f;
  p = p * f + 6.9314718e-1f;
  return p * f + 1.0f;
}

/// exp(x) for x <= 0 (relative error < 2e-7 for x > -87; 0 below). Cody-Waite split into
/// 2^k * 2^f with a degree-6 polynomial for 2^f on [-0.5, 0.5].
inline float fast_exp_neg(float x) {
  const bool in_range = x > -87.0f;  // false for NaN too
  const float xc = in_range ? x : -87.0f;  // branch-free: the result is selected below
  const float t = xc * 1.44269504f;  // x / ln 2
  const float k = round_nearest(t);
  const float f = t - k;  // [-0.5, 0.5]
  const float p = exp2_poly(f);
  const std::int32_t bits = (static_cast<std::int32_t>(k) + 127) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return in_range ? p * scale : 0.0f;
}

/// Four floats / int32 as one SIMD value (GCC and Clang vector extensions: SSE2 on x86-64, NEON
/// on arm64). For the loops the compiler will not vectorise itself: reductions (no reordering
/// without -ffast-math) and selects around trapping arithmetic (never if-converted).
typedef float Float4 __attribute__((vector_size(16)));
typedef std::int32_t Int4 __attribute__((vector_size(16)));

inline Float4 load4(const float* p) {
  Float4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store4(float* p, Float4 v) { std::memcpy(p, &v, sizeof v); }
inline Float4 splat4(float x) { return Float4{x, x, x, x}; }
/// mask ? a : b per lane (mask lanes all ones or zero, as comparisons give).
inline Float4 select4(Int4 mask, Float4 a, Float4 b) {
  return reinterpret_cast<Float4>((reinterpret_cast<Int4>(a) & mask) | (reinterpret_cast<Int4>(b) & ~mask));
}

/// fast_exp_neg on four lanes, the same operations in the same order (same results).
inline Float4 fast_exp_neg4(Float4 x) {
  const Int4 in_range = x > splat4(-87.0f);  // false for NaN
  const Float4 xc = select4(in_range, x, splat4(-87.0f));
  const Float4 t = xc * 1.44269504f;
  const Float4 k = (t + 12582912.0f) - 12582912.0f;  // round_nearest
  const Float4 f = t - k;
  const Float4 p = exp2_poly(f);
  const Int4 bits = (__builtin_convertvector(k, Int4) + 127) << 23;
  return select4(in_range, p * reinterpret_cast<Float4>(bits), splat4(0.0f));
}

/// sin and cos of x in [-pi, pi] through the half angle (Taylor to degree 9/10 on
/// [-pi/2, pi/2]); absolute error < 1e-5.
inline void fast_sincos(float x, float& s_out, float& c_out) {
  const float h = 0.5f * x;
  const float h2 = h * h;
  const float s = h * (1.0f + h2 * (-1.0f / 6 + h2 * (1.0f / 120 + h2 * (-1.0f / 5040 + h2 * (1.0f / 362880)))));
  const float c = 1.0f + h2 * (-0.5f + h2 * (1.0f / 24 + h2 * (-1.0f / 720 + h2 * (1.0f / 40320 + h2 * (-1.0f / 3628800)))));
  s_out = 2.0f * s * c;
  c_out = c * c - s * s;
}

/// Wrap an angle to [-pi, pi] without branches.
inline float wrap_pi_f(float x) {
  constexpr float two_pi = 6.28318531f;
  return x - two_pi * round_nearest(x * (1.0f / two_pi));
}

}  // namespace pdnav::terrain::detail
