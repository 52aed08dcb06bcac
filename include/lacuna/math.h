// Small fixed-size vector types used across the public API. Plain aggregates, no SIMD
// (the SIMD kernels live in src/core/simd_lanes.h).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace lacuna {

template <class T>
struct Vec3 {
    T x{}, y{}, z{};
    constexpr T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr const T& operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    friend constexpr Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend constexpr Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend constexpr Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
    friend constexpr Vec3 operator/(Vec3 a, Vec3 b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }
    friend constexpr Vec3 operator*(Vec3 a, T s) { return {a.x * s, a.y * s, a.z * s}; }
    friend constexpr Vec3 operator*(T s, Vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
    friend constexpr Vec3 operator/(Vec3 a, T s) { return {a.x / s, a.y / s, a.z / s}; }
    friend constexpr Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
    friend constexpr bool operator==(Vec3 a, Vec3 b) {
        return a.x == b.x && a.y == b.y && a.z == b.z;
    }
    template <class U>
    constexpr explicit operator Vec3<U>() const {
        return {static_cast<U>(x), static_cast<U>(y), static_cast<U>(z)};
    }
};
using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;
using Vec3i = Vec3<int>;

template <class T>
constexpr T dot(Vec3<T> a, Vec3<T> b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
constexpr Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
inline T length(Vec3<T> a) {
    return std::sqrt(dot(a, a));
}
template <class T>
inline Vec3<T> normalize(Vec3<T> a) {
    return a / length(a);
}
template <class T>
constexpr Vec3<T> vmin(Vec3<T> a, Vec3<T> b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <class T>
constexpr Vec3<T> vmax(Vec3<T> a, Vec3<T> b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <class T>
inline std::string to_string(Vec3<T> v) {
    return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) +
           ")";
}

// An axis-aligned box [lo, hi] (inclusive bounds, lo <= hi on every axis when non-empty).
template <class T>
struct Box3 {
    Vec3<T> lo{}, hi{};
    constexpr Vec3<T> extent() const { return hi - lo; }
    constexpr Vec3<T> center() const { return (lo + hi) / T(2); }
};
using Box3f = Box3<float>;
using Box3i = Box3<int>;

}  // namespace lacuna
