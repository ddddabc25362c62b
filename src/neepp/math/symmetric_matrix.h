// A symmetric 3x3 matrix in the six numbers Mitsuba 3 stores it as (a 6-channel volume's value, the SGGX
// microflake distribution's S): xx, yy, zz, xy, xz, yz.
#pragma once
#include <array>
#include "neepp/math/vec.h"

namespace neepp {

struct SymmetricMatrix3 {
    float xx = 0, yy = 0, zz = 0, xy = 0, xz = 0, yz = 0;

    SymmetricMatrix3() = default;
    constexpr SymmetricMatrix3(float xx_, float yy_, float zz_, float xy_, float xz_, float yz_)
        : xx(xx_), yy(yy_), zz(zz_), xy(xy_), xz(xz_), yz(yz_) {}
    // In Mitsuba's order: S_xx, S_yy, S_zz, S_xy, S_xz, S_yz.
    static SymmetricMatrix3 from_channels(const float *v) { return {v[0], v[1], v[2], v[3], v[4], v[5]}; }
    std::array<float, 6> channels() const { return {xx, yy, zz, xy, xz, yz}; }

    // Linear combinations: what trilinear interpolation of a grid of them needs.
    SymmetricMatrix3 operator+(const SymmetricMatrix3 &o) const {
        return {xx + o.xx, yy + o.yy, zz + o.zz, xy + o.xy, xz + o.xz, yz + o.yz};
    }
    SymmetricMatrix3 operator*(float s) const { return {xx * s, yy * s, zz * s, xy * s, xz * s, yz * s}; }
    bool operator==(const SymmetricMatrix3 &o) const = default;

    Vec3 operator*(const Vec3 &v) const {
        return {xx * v.x + xy * v.y + xz * v.z, xy * v.x + yy * v.y + yz * v.z, xz * v.x + yz * v.y + zz * v.z};
    }
    // vᵀ S w.
    float form(const Vec3 &v, const Vec3 &w) const { return dot(v, *this * w); }
    float determinant() const {
        return xx * yy * zz + 2.f * xy * xz * yz - xx * yz * yz - yy * xz * xz - zz * xy * xy;
    }
    // The adjugate (the cofactor matrix, itself symmetric): det(S) S⁻¹ where S is invertible, and still
    // defined where it is not (a flat or a fibre-like SGGX with an eigenvalue of 0).
    SymmetricMatrix3 adjugate() const {
        return {yy * zz - yz * yz, xx * zz - xz * xz, xx * yy - xy * xy,
                xz * yz - zz * xy, xy * yz - yy * xz, xy * xz - xx * yz};
    }
};

// The three eigenvalues, smallest first, in double precision (the closed form for symmetric 3x3
// matrices: the roots of the characteristic cubic by the trigonometric method).
std::array<double, 3> eigenvalues(const SymmetricMatrix3 &s);

}  // namespace neepp
