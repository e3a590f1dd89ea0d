#include "u4d/synth/texture.h"

#include <algorithm>
#include <cmath>

#include "u4d/util/check.h"

namespace u4d::synth {
namespace {

inline uint32_t Mix(uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352dU;
  h ^= h >> 15;
  h *= 0x846ca68bU;
  h ^= h >> 16;
  return h;
}

// Lattice hash: one avalanche round over a linear combination of the
// coordinates (large odd multipliers) and the pre-mixed seed.
inline uint32_t LatticeHash(int x, int y, int z, uint32_t mixed_seed) {
  return Mix(static_cast<uint32_t>(x) * 0x8da6b343U + static_cast<uint32_t>(y) * 0xd8163841U +
             static_cast<uint32_t>(z) * 0xcb1ab31fU + mixed_seed);
}

inline uint32_t Hash3(int x, int y, int z, uint32_t seed) {
  return LatticeHash(x, y, z, Mix(seed ^ 0x9e3779b9U));
}

// Uniform in [0, 1) from a hash.
inline float Unit(uint32_t h) { return static_cast<float>(h >> 8) * (1.0f / 16777216.0f); }

// Brings the simplex sum to roughly [-1, 1] (measured maximum ~0.9).
constexpr float kSimplexScale = 62.0f;

// Dot product of one of the 8 gradients (+-1, +-1, +-1) * 0.7 with (x, y, z),
// signs from three hash bits (branch-free).
inline float Grad(uint32_t h, float x, float y, float z) {
  const float gx = (h & 1) ? x : -x, gy = (h & 2) ? y : -y, gz = (h & 4) ? z : -z;
  return 0.7f * (gx + gy + gz);
}

// floor() without a libm call (inputs are far inside the int range).
inline int FastFloor(float v) {
  const int i = static_cast<int>(v);
  return i - (v < static_cast<float>(i));
}

inline float Clamp01(float v) { return std::min(1.0f, std::max(0.0f, v)); }
inline float Smoothstep(float e0, float e1, float x) {
  const float t = Clamp01((x - e0) / (e1 - e0));
  return t * t * (3 - 2 * t);
}

// Weight of a feature of period `period` seen with pixel footprint `footprint`:
// 1 above 4 footprints, 0 below 2.
inline float BandWeight(float period, float footprint) {
  if (footprint <= 0) return 1.0f;
  return Clamp01(period / footprint * 0.5f - 1.0f);
}

// Square wave of period 1 (1 on [0, 0.5), 0 on [0.5, 1)) box-filtered over width w.
inline float SquareIntegral(float x) {
  const float f = std::floor(x);
  return 0.5f * f + std::min(x - f, 0.5f);
}
inline float FilteredSquare(float x, float w) {
  if (w < 1e-4f) return (x - std::floor(x)) < 0.5f ? 1.0f : 0.0f;
  if (w >= 1.0f) return 0.5f;  // wider than a period: the mean
  return (SquareIntegral(x + 0.5f * w) - SquareIntegral(x - 0.5f * w)) / w;
}

Eigen::Vector3f Blend(const Material& m, float t) {
  return m.color_a + Clamp01(t) * (m.color_b - m.color_a);
}

// Fine detail factor around 1 for the geometric patterns.
float Detail(const Material& m, const Eigen::Vector3f& p, float footprint) {
  return 1.0f + 0.2f * 1.6f * FractalNoise(p, m.scale * 0.25f, m.seed ^ 0x51ed270bU, 2, footprint);
}

}  // namespace

float GradientNoise(float x, float y, float z, uint32_t seed) {
  // Simplex noise (4 lattice corners per sample instead of 8): skew to the
  // cubic lattice, find the simplex, sum radially attenuated gradient ramps.
  constexpr float kF3 = 1.0f / 3.0f, kG3 = 1.0f / 6.0f;
  const float skew = (x + y + z) * kF3;
  const int i = FastFloor(x + skew), j = FastFloor(y + skew), k = FastFloor(z + skew);
  const float fi = static_cast<float>(i), fj = static_cast<float>(j), fk = static_cast<float>(k);
  const float unskew = (fi + fj + fk) * kG3;
  const float x0 = x - (fi - unskew), y0 = y - (fj - unskew), z0 = z - (fk - unskew);
  // Offsets of the second and third simplex corners (branch-free ordering).
  const int xy = x0 >= y0, xz = x0 >= z0, yz = y0 >= z0;
  const int i1 = xy & xz, j1 = (1 - xy) & yz, k1 = (1 - xz) & (1 - yz);
  const int i2 = xy | xz, j2 = (1 - xy) | yz, k2 = (1 - xz) | (1 - yz);
  const float x1 = x0 - i1 + kG3, y1 = y0 - j1 + kG3, z1 = z0 - k1 + kG3;
  const float x2 = x0 - i2 + 2 * kG3, y2 = y0 - j2 + 2 * kG3, z2 = z0 - k2 + 2 * kG3;
  const float x3 = x0 - 1 + 3 * kG3, y3 = y0 - 1 + 3 * kG3, z3 = z0 - 1 + 3 * kG3;
  const uint32_t s = Mix(seed ^ 0x9e3779b9U);
  auto corner = [](uint32_t h, float cx, float cy, float cz) {
    float t = std::max(0.0f, 0.5f - cx * cx - cy * cy - cz * cz);  // support radius^2 0.5
    t *= t;
    return t * t * Grad(h, cx, cy, cz);
  };
  const float n = corner(LatticeHash(i, j, k, s), x0, y0, z0) +
                  corner(LatticeHash(i + i1, j + j1, k + k1, s), x1, y1, z1) +
                  corner(LatticeHash(i + i2, j + j2, k + k2, s), x2, y2, z2) +
                  corner(LatticeHash(i + 1, j + 1, k + 1, s), x3, y3, z3);
  return kSimplexScale * n;
}

float FractalNoise(const Eigen::Vector3f& p, float period, uint32_t seed, int max_octaves,
                   float footprint) {
  float sum = 0, norm = 0, amplitude = 1;
  for (int o = 0; o < max_octaves; ++o) {
    norm += amplitude;
    const float weight = BandWeight(period, footprint);
    if (weight > 0) {
      const float inv = 1.0f / period;
      sum += weight * amplitude *
             GradientNoise(p.x() * inv, p.y() * inv, p.z() * inv, seed + 1013u * o);
    }
    period *= 0.5f;
    amplitude *= 0.5f;
  }
  return sum / norm;
}

Eigen::Vector3f EvaluateMaterial(const Material& m, const Eigen::Vector3f& tc, float footprint) {
  U4D_CHECK(std::isfinite(m.scale) && m.scale > 0,
            "EvaluateMaterial: material scale must be positive and finite, got {}", m.scale);
  const float fp = std::max(0.0f, footprint);
  switch (m.pattern) {
    case Material::Pattern::kPlain:
      return m.color_a;
    case Material::Pattern::kNoise: {
      // 1.6 stretches the narrow distribution of fractal noise to use the contrast.
      const float n = FractalNoise(tc, m.scale, m.seed, kMaxOctaves, fp);
      return Blend(m, 0.5f + 1.6f * n);
    }
    case Material::Pattern::kStripes: {
      // Seeded direction on the sphere and phase.
      const uint32_t h = Hash3(1, 2, 3, m.seed);
      const float cz = 2 * Unit(h) - 1, phi = 6.2831853f * Unit(Mix(h));
      const float sz = std::sqrt(std::max(0.0f, 1 - cz * cz));
      const Eigen::Vector3f dir(sz * std::cos(phi), sz * std::sin(phi), cz);
      const float x = dir.dot(tc) / m.scale + Unit(Mix(h + 7));
      return Blend(m, FilteredSquare(x, fp / m.scale)) * Detail(m, tc, fp);
    }
    case Material::Pattern::kChecker: {
      const uint32_t h = Hash3(4, 5, 6, m.seed);
      const float w = fp / m.scale;
      const Eigen::Vector3f q = tc / m.scale;
      const float a = FilteredSquare(q.x() + Unit(h), w);
      const float b = FilteredSquare(q.y() + Unit(Mix(h)), w);
      const float c = FilteredSquare(q.z() + Unit(Mix(h + 1)), w);
      // XOR of three square waves; exact box filter because it is separable.
      const float t = 0.5f - 0.5f * (1 - 2 * a) * (1 - 2 * b) * (1 - 2 * c);
      return Blend(m, t) * Detail(m, tc, fp);
    }
    case Material::Pattern::kSpots: {
      // One ball per cubic cell, centre anywhere in the cell, radius < 0.5 cell:
      // only the own cell and the nearer neighbour along each axis can reach q.
      const Eigen::Vector3f q = tc / m.scale;
      const float soft = std::max(0.5f * fp / m.scale, 0.02f);
      const int base[3] = {static_cast<int>(std::floor(q.x())), static_cast<int>(std::floor(q.y())),
                           static_cast<int>(std::floor(q.z()))};
      int step[3];
      for (int k = 0; k < 3; ++k) step[k] = (q[k] - base[k]) < 0.5f ? -1 : 1;
      float t = 0;
      for (int corner = 0; corner < 8; ++corner) {
        const int ix = base[0] + ((corner & 1) ? step[0] : 0);
        const int iy = base[1] + ((corner & 2) ? step[1] : 0);
        const int iz = base[2] + ((corner & 4) ? step[2] : 0);
        const uint32_t h = Hash3(ix, iy, iz, m.seed ^ 0xa5a5a5a5U);
        const float radius = 0.2f + 0.15f * Unit(h);
        const uint32_t h1 = Mix(h), h2 = Mix(h1), h3 = Mix(h2);
        const Eigen::Vector3f centre(ix + Unit(h1), iy + Unit(h2), iz + Unit(h3));
        const float d = (q - centre).norm();
        t = std::max(t, 1.0f - Smoothstep(radius - soft, radius + soft, d));
      }
      // When a cell is smaller than a few pixels, fade to the mean coverage
      // (the mean ball volume, 4/3 pi E[r^3] ~ 0.094 of a cell).
      const float weight = BandWeight(m.scale, fp);
      t = weight * t + (1 - weight) * 0.094f;
      return Blend(m, t) * Detail(m, tc, fp);
    }
  }
  return m.color_a;
}

}  // namespace u4d::synth
