// Surface shading of volume samples (docs/shading.md): Blinn-Phong, and the bitfield paper's
// physically based model (Section 4.4, after Unity's Standard Shader): Disney diffuse [Bur12],
// GGX normal distribution [WMLT07], Smith joint GGX visibility [Hei14], Schlick Fresnel [Sch94].
//
// Conventions: all vectors in world space, unit length. N is the surface normal estimated from
// the gradient (N = -grad/|grad|, pointing from high to low values), flipped toward the viewer
// (two-sided lighting: a shell is lit from inside and outside alike). L points to the light, V
// to the eye. Colours are linear RGB; the result is not clamped (the image writer clamps).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/spec_pow.h"
#include "lacuna/math.h"
#include "lacuna/renderer.h"

namespace lacuna::shading {

inline constexpr float kPi = 3.14159265358979f;

// The normal from a world-space gradient, facing the viewer; false when the gradient is zero
// (no surface: the sample keeps its TF colour).
inline bool normal_from_gradient(Vec3f g, Vec3f view, Vec3f& n) {
    const float len2 = dot(g, g);
    if (!(len2 > 0.f)) return false;
    n = g * (-1.f / std::sqrt(len2));
    if (dot(n, view) < 0.f) n = -n;
    return true;
}

// Blinn-Phong: rgb*(ambient + diffuse*Li*max(N.L,0)) + specular*Li*max(N.H,0)^power.
// `li` is the light's intensity at the sample (spot falloff and shadowing applied). `hn` is the
// unit half vector (l + v)/|l + v|, used only when `h_ok` (|l + v| > 0): phong() computes it per
// sample; the feature kernel's batched path once per ray when l and v are fixed (same bits).
inline Vec3f phong_h(const PhongParams& p, Vec3f rgb, Vec3f n, Vec3f l, Vec3f hn, bool h_ok,
                     float li) {
    const float ndl = std::max(dot(n, l), 0.f);
    float spec = 0.f;
    if (ndl > 0.f && h_ok) spec = simd::spec_pow(std::max(dot(n, hn), 0.f), p.power);
    const float k = p.ambient + p.diffuse * li * ndl;
    const float s = p.specular * li * spec;
    return {rgb.x * k + s, rgb.y * k + s, rgb.z * k + s};
}

// The half vector of phong() and pbr(): (l + v)/|l + v|, and whether |l + v| > 0.
inline bool half_vector(Vec3f l, Vec3f v, Vec3f& hn) {
    const Vec3f h = l + v;
    const float hl = length(h);
    if (!(hl > 0.f)) return false;
    hn = h / hl;
    return true;
}

inline Vec3f phong(const PhongParams& p, Vec3f rgb, Vec3f n, Vec3f l, Vec3f v, float li) {
    Vec3f hn{0, 0, 0};
    const bool h_ok = half_vector(l, v, hn);
    return phong_h(p, rgb, n, l, hn, h_ok, li);
}

// Disney diffuse (Burley 2012), without the 1/pi (Unity's convention: the light's intensity is
// its radiance times pi).
inline float disney_diffuse(float ndv, float ndl, float ldh, float roughness) {
    const float fd90 = 0.5f + 2.f * ldh * ldh * roughness;
    const float lv = 1.f - ndl, vv = 1.f - ndv;
    const float fl = 1.f + (fd90 - 1.f) * lv * lv * lv * lv * lv;
    const float fv = 1.f + (fd90 - 1.f) * vv * vv * vv * vv * vv;
    return fl * fv;
}

// GGX / Trowbridge-Reitz normal distribution, alpha = roughness^2.
inline float ggx_d(float ndh, float alpha) {
    const float a2 = alpha * alpha;
    const float d = ndh * ndh * (a2 - 1.f) + 1.f;
    return a2 / (kPi * d * d + 1e-7f);
}

// Smith joint GGX visibility term V = G / (4 N.L N.V) (Heitz 2014, Eq. 99).
inline float smith_joint_ggx_v(float ndl, float ndv, float alpha) {
    const float a2 = alpha * alpha;
    const float gl = ndv * std::sqrt(ndl * ndl * (1.f - a2) + a2);
    const float gv = ndl * std::sqrt(ndv * ndv * (1.f - a2) + a2);
    return 0.5f / (gl + gv + 1e-5f);
}

// Schlick's Fresnel approximation for reflectance f0 at normal incidence.
inline float schlick(float f0, float ldh) {
    const float m = 1.f - ldh;
    return f0 + (1.f - f0) * m * m * m * m * m;
}

// The physically based model: albedo*(1-metallic) * (ambient + Li * Disney * N.L)
//   + Li * pi * D * V * F * N.L,  F0 = lerp(0.04, albedo, metallic).
// `h` is the unit half vector (n where l + v = 0): pbr() computes it per sample, the batched
// path once per ray when l and v are fixed (same bits).
inline Vec3f pbr_h(const PbrParams& p, Vec3f albedo, Vec3f n, Vec3f l, Vec3f v, Vec3f h, float li) {
    const float rough = std::clamp(p.roughness, 0.02f, 1.f);
    const float alpha = rough * rough;
    const float ndl = std::max(dot(n, l), 0.f);
    const float ndv = std::max(dot(n, v), 1e-4f);
    const float ndh = std::max(dot(n, h), 0.f), ldh = std::max(dot(l, h), 0.f);
    const float diffuse = li * disney_diffuse(ndv, ndl, ldh, rough) * ndl;
    const float spec_common =
        li * kPi * ggx_d(ndh, alpha) * smith_joint_ggx_v(ndl, ndv, alpha) * ndl;
    const float m = std::clamp(p.metallic, 0.f, 1.f);
    const float c[3] = {albedo.x, albedo.y, albedo.z};
    float out[3];
    for (int i = 0; i < 3; ++i) {
        const float f0 = 0.04f * (1.f - m) + c[i] * m;
        const float kd = c[i] * (1.f - m);
        out[i] = kd * (p.ambient + diffuse) + spec_common * schlick(f0, ldh);
    }
    return {out[0], out[1], out[2]};
}

inline Vec3f pbr(const PbrParams& p, Vec3f albedo, Vec3f n, Vec3f l, Vec3f v, float li) {
    Vec3f h = n;
    half_vector(l, v, h);
    return pbr_h(p, albedo, n, l, v, h, li);
}

// Spot falloff: 1 inside 0.8*cone, 0 outside the cone, smoothstep between.
inline float spot_factor(float cos_angle, float cone_deg) {
    const float c_out = std::cos(cone_deg * kPi / 180.f),
                c_in = std::cos(0.8f * cone_deg * kPi / 180.f);
    if (cos_angle <= c_out) return 0.f;
    if (cos_angle >= c_in) return 1.f;
    const float x = (cos_angle - c_out) / (c_in - c_out);
    return x * x * (3.f - 2.f * x);
}

// g(|grad|) of GradientOpacity (lacuna/renderer.h): the piecewise-linear factor over n >= 1
// points sorted by x. Written lo.a + (hi.a - lo.a) * ((mag - lo.x) / (hi.x - lo.x)) so that
//   - the ramp (lo, 0), (hi, 1) gives bit for bit the old ramp's (mag - lo) / (hi - lo)
//     (0 + 1 * t is t in float), so --gradient-opacity LO,HI images did not change;
//   - a stretch between two equal factors returns that factor exactly (0 * t is 0), so a zero
//     stretch is exactly zero and a stretch of ones exactly one.
// The scan is linear: presets have 2..6 points. No allocation (the kernel calls it per sample).
inline float gradient_opacity(const GradientOpacityPoint* p, size_t n, float mag) {
    if (mag < p[0].x) return p[0].a;  // left of the first point: its value
    size_t i = 1;                     // the first point strictly right of mag
    while (i < n && p[i].x <= mag) ++i;
    if (i == n) return p[n - 1].a;  // at or right of the last point: its value
    const GradientOpacityPoint& lo = p[i - 1];
    const GradientOpacityPoint& hi = p[i];  // lo.x <= mag < hi.x: a positive width
    return lo.a + (hi.a - lo.a) * ((mag - lo.x) / (hi.x - lo.x));
}

inline float gradient_opacity(const GradientOpacity& g, float mag) {
    if (!g.points.empty()) return gradient_opacity(g.points.data(), g.points.size(), mag);
    const GradientOpacityPoint ramp[2] = {{g.lo, 0.f}, {g.hi, 1.f}};
    return gradient_opacity(ramp, 2, mag);
}

}  // namespace lacuna::shading
