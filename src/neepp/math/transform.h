// 4x4 affine/projective transforms (row-major), as used by Mitsuba's <transform> element.
#pragma once
#include <array>
#include <string>
#include "neepp/math/vec.h"

namespace neepp {

struct Matrix4 {
    std::array<std::array<float, 4>, 4> m{};
    static Matrix4 identity();
    Matrix4 operator*(const Matrix4 &o) const;
    Matrix4 inverse() const;  // general inverse; throws std::runtime_error on a singular matrix
    Matrix4 transpose() const;
};

struct Transform;
// The scale of a to_world that scales all directions alike (it may also translate, rotate and mirror);
// throws std::runtime_error, naming it (what), for one that shears or scales some directions more than others.
float uniform_scale(const Transform &to_world, const std::string &what);

struct Transform {
    Matrix4 matrix = Matrix4::identity(), inverse_matrix = Matrix4::identity();
    Transform() = default;
    explicit Transform(const Matrix4 &m) : matrix(m), inverse_matrix(m.inverse()) {}
    Transform(const Matrix4 &m, const Matrix4 &inv) : matrix(m), inverse_matrix(inv) {}

    static Transform translate(const Vec3 &d);
    static Transform scale(const Vec3 &s);
    static Transform rotate(const Vec3 &axis, float degrees);
    // Mitsuba's lookat: camera at origin looking down +z becomes camera at `origin` looking at `target`.
    static Transform look_at(const Vec3 &origin, const Vec3 &target, const Vec3 &up);

    Transform operator*(const Transform &o) const { return {matrix * o.matrix, o.inverse_matrix * inverse_matrix}; }
    Transform inverse() const { return {inverse_matrix, matrix}; }

    Vec3 point(const Vec3 &p) const;
    // Inline, with inverse_vector: the environment map turns every direction it samples or looks up.
    Vec3 vector(const Vec3 &v) const { return linear(matrix, v); }
    // The inverse's vector(v), from the inverse matrix kept here (inverse() would copy both matrices).
    Vec3 inverse_vector(const Vec3 &v) const { return linear(inverse_matrix, v); }
    // Normals transform by the inverse transpose.
    Vec3 normal(const Vec3 &n) const;
    // Whether the transform flips orientation (negative determinant of the linear part).
    bool flips_handedness() const;
    // Whether the linear part is a rotation, or one with a reflection (orthonormal columns, to tolerance):
    // then vector() keeps unit vectors unit.
    bool preserves_lengths(float tolerance = 1e-6f) const;

private:
    static Vec3 linear(const Matrix4 &m, const Vec3 &v) {
        const auto &a = m.m;
        return {a[0][0] * v.x + a[0][1] * v.y + a[0][2] * v.z, a[1][0] * v.x + a[1][1] * v.y + a[1][2] * v.z,
                a[2][0] * v.x + a[2][1] * v.y + a[2][2] * v.z};
    }
};

}  // namespace neepp
