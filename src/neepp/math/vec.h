// Small fixed-size vector types used everywhere in the renderer.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace neepp {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr float kInv2Pi = 0.15915494309189533577f;
constexpr float kInv4Pi = 0.07957747154594766788f;
constexpr float kInfinity = 1e30f;
// The largest float below 1: a uniform rescaled into [0, 1) stays below 1.
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

struct Vec2 {
    float x = 0, y = 0;
    Vec2() = default;
    constexpr Vec2(float x_, float y_) : x(x_), y(y_) {}
    Vec2 operator+(Vec2 o) const { return {x + o.x, y + o.y}; }
    Vec2 operator-(Vec2 o) const { return {x - o.x, y - o.y}; }
    Vec2 operator*(float s) const { return {x * s, y * s}; }
    float operator[](int i) const { return i == 0 ? x : y; }
};

struct Vec3 {
    float x = 0, y = 0, z = 0;
    Vec3() = default;
    constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3(float s) : x(s), y(s), z(s) {}
    float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    float &operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    Vec3 operator+(const Vec3 &o) const { return {x + o.x, y + o.y, z + o.z}; }
    Vec3 operator-(const Vec3 &o) const { return {x - o.x, y - o.y, z - o.z}; }
    Vec3 operator*(const Vec3 &o) const { return {x * o.x, y * o.y, z * o.z}; }
    Vec3 operator/(const Vec3 &o) const { return {x / o.x, y / o.y, z / o.z}; }
    Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
    Vec3 operator/(float s) const { float r = 1.f / s; return {x * r, y * r, z * r}; }
    Vec3 operator-() const { return {-x, -y, -z}; }
    Vec3 &operator+=(const Vec3 &o) { x += o.x; y += o.y; z += o.z; return *this; }
    Vec3 &operator-=(const Vec3 &o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    Vec3 &operator*=(const Vec3 &o) { x *= o.x; y *= o.y; z *= o.z; return *this; }
    Vec3 &operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
    Vec3 &operator/=(float s) { return *this *= (1.f / s); }
    bool operator==(const Vec3 &o) const { return x == o.x && y == o.y && z == o.z; }
};

inline Vec3 operator*(float s, const Vec3 &v) { return v * s; }
inline float dot(const Vec3 &a, const Vec3 &b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline float absdot(const Vec3 &a, const Vec3 &b) { return std::abs(dot(a, b)); }
inline Vec3 cross(const Vec3 &a, const Vec3 &b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float squared_norm(const Vec3 &v) { return dot(v, v); }
inline float norm(const Vec3 &v) { return std::sqrt(dot(v, v)); }
inline Vec3 normalize(const Vec3 &v) { return v / norm(v); }
inline Vec3 vmin(const Vec3 &a, const Vec3 &b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3 vmax(const Vec3 &a, const Vec3 &b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline float max_component(const Vec3 &v) { return std::max(v.x, std::max(v.y, v.z)); }
inline Vec3 vexp(const Vec3 &v) { return {std::exp(v.x), std::exp(v.y), std::exp(v.z)}; }
inline bool is_finite(const Vec3 &v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline Vec3 reflect(const Vec3 &v, const Vec3 &n) { return 2.f * dot(v, n) * n - v; }
inline Vec3 lerp(float t, const Vec3 &a, const Vec3 &b) { return (1 - t) * a + t * b; }
inline float safe_sqrt(float v) { return std::sqrt(std::max(0.f, v)); }
inline float sqr(float v) { return v * v; }

// An RGB triple of radiance, reflectance or throughput. Same layout as Vec3, separate name for intent.
using Color = Vec3;
inline float luminance(const Color &c) { return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z; }
inline bool is_black(const Color &c) { return c.x == 0 && c.y == 0 && c.z == 0; }

}  // namespace neepp
