// Solid textures: evaluates a Material (synth/scene.h) at a 3D texcoord.
//
// Patterns (period = Material::scale metres of texcoord, seeded by Material::seed):
//  kPlain    color_a everywhere (genuinely textureless).
//  kNoise    fractal gradient noise blending color_a and color_b; kMaxOctaves
//            octaves of period scale, scale/2, scale/4, scale/8.
//  kStripes  stripes of period `scale` along a seed-dependent direction.
//  kChecker  3D checkerboard with cells of scale/2 (period `scale`), phase from seed.
//  kSpots    one spot of color_b per cubic cell of size `scale`, random centre
//            and radius, on color_a.
// Stripes, checker and spots are modulated by fine fractal detail (periods
// scale/4 and scale/8, about +-20% brightness) so that they carry the high frequencies
// photo-consistency matching needs.
//
// Band limiting: `footprint` is the size (metres of texcoord) one pixel covers.
// Noise octaves with a period below 4 footprints fade out (gone at 2), and the
// hard edges of stripes/checker/spots are box-filtered over the footprint, so
// textures do not alias at any distance. footprint = 0 gives full detail
// (noise capped at kMaxOctaves octaves).
//
// Everything is deterministic: the same material and texcoord give the same colour.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "u4d/synth/scene.h"

namespace u4d::synth {

inline constexpr int kMaxOctaves = 4;

// Linear BGR in [0, 1]. Throws u4d::Error when material.scale is not positive
// and finite.
Eigen::Vector3f EvaluateMaterial(const Material& material, const Eigen::Vector3f& texcoord,
                                 float footprint = 0.0f);

// Gradient noise on a unit (skewed simplex) lattice, in about [-1, 1], zero
// at simplex-lattice points, smooth (C1) everywhere (simplex noise).
float GradientNoise(float x, float y, float z, uint32_t seed);

// Sum of `max_octaves` octaves of GradientNoise of the point p / period,
// period halving and amplitude halving per octave, each octave faded by the
// footprint as above. Normalised so the sum of amplitudes is 1.
float FractalNoise(const Eigen::Vector3f& p, float period, uint32_t seed, int max_octaves,
                   float footprint);

}  // namespace u4d::synth
