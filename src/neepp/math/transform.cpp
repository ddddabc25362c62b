#include "neepp/math/transform.h"

#include <cmath>

#include <stdexcept>

namespace neepp {

Matrix4 Matrix4::identity() {
    Matrix4 r;
    for (int i = 0; i < 4; ++i) r.m[i][i] = 1.f;
    return r;
}

Matrix4 Matrix4::operator*(const Matrix4 &o) const {
    Matrix4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += double(m[i][k]) * o.m[k][j];
            r.m[i][j] = float(s);
        }
    return r;
}

Matrix4 Matrix4::transpose() const {
    Matrix4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = m[j][i];
    return r;
}

Matrix4 Matrix4::inverse() const {
    // Gauss-Jordan elimination with partial pivoting, in double precision.
    double a[4][8];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 8; ++j) a[i][j] = j < 4 ? m[i][j] : (j - 4 == i ? 1.0 : 0.0);
    for (int c = 0; c < 4; ++c) {
        int piv = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::abs(a[r][c]) > std::abs(a[piv][c])) piv = r;
        if (std::abs(a[piv][c]) < 1e-30) throw std::runtime_error("singular transform matrix");
        if (piv != c)
            for (int j = 0; j < 8; ++j) std::swap(a[c][j], a[piv][j]);
        double inv = 1.0 / a[c][c];
        for (int j = 0; j < 8; ++j) a[c][j] *= inv;
        for (int r = 0; r < 4; ++r) {
            if (r == c) continue;
            double f = a[r][c];
            if (f != 0)
                for (int j = 0; j < 8; ++j) a[r][j] -= f * a[c][j];
        }
    }
    Matrix4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[i][j] = float(a[i][j + 4]);
    return r;
}

Transform Transform::translate(const Vec3 &d) {
    Matrix4 m = Matrix4::identity(), inv = Matrix4::identity();
    for (int i = 0; i < 3; ++i) { m.m[i][3] = d[i]; inv.m[i][3] = -d[i]; }
    return {m, inv};
}

Transform Transform::scale(const Vec3 &s) {
    Matrix4 m = Matrix4::identity(), inv = Matrix4::identity();
    for (int i = 0; i < 3; ++i) { m.m[i][i] = s[i]; inv.m[i][i] = 1.f / s[i]; }
    return {m, inv};
}

Transform Transform::rotate(const Vec3 &axis_in, float degrees) {
    Vec3 a = normalize(axis_in);
    float rad = degrees * kPi / 180.f, s = std::sin(rad), c = std::cos(rad);
    Matrix4 m = Matrix4::identity();
    m.m[0][0] = a.x * a.x + (1 - a.x * a.x) * c;
    m.m[0][1] = a.x * a.y * (1 - c) - a.z * s;
    m.m[0][2] = a.x * a.z * (1 - c) + a.y * s;
    m.m[1][0] = a.x * a.y * (1 - c) + a.z * s;
    m.m[1][1] = a.y * a.y + (1 - a.y * a.y) * c;
    m.m[1][2] = a.y * a.z * (1 - c) - a.x * s;
    m.m[2][0] = a.x * a.z * (1 - c) - a.y * s;
    m.m[2][1] = a.y * a.z * (1 - c) + a.x * s;
    m.m[2][2] = a.z * a.z + (1 - a.z * a.z) * c;
    return {m, m.transpose()};
}

Transform Transform::look_at(const Vec3 &origin, const Vec3 &target, const Vec3 &up) {
    Vec3 dir = normalize(target - origin);
    Vec3 left = cross(normalize(up), dir);
    if (squared_norm(left) < 1e-12f) throw std::runtime_error("lookat: 'up' is parallel to the view direction");
    left = normalize(left);
    Vec3 new_up = cross(dir, left);
    Matrix4 m = Matrix4::identity();
    for (int i = 0; i < 3; ++i) {
        m.m[i][0] = left[i];
        m.m[i][1] = new_up[i];
        m.m[i][2] = dir[i];
        m.m[i][3] = origin[i];
    }
    return Transform(m);
}

Vec3 Transform::point(const Vec3 &p) const {
    const auto &a = matrix.m;
    Vec3 r(a[0][0] * p.x + a[0][1] * p.y + a[0][2] * p.z + a[0][3],
           a[1][0] * p.x + a[1][1] * p.y + a[1][2] * p.z + a[1][3],
           a[2][0] * p.x + a[2][1] * p.y + a[2][2] * p.z + a[2][3]);
    float w = a[3][0] * p.x + a[3][1] * p.y + a[3][2] * p.z + a[3][3];
    return w == 1.f ? r : r / w;
}

Vec3 Transform::normal(const Vec3 &n) const {
    const auto &a = inverse_matrix.m;
    return {a[0][0] * n.x + a[1][0] * n.y + a[2][0] * n.z, a[0][1] * n.x + a[1][1] * n.y + a[2][1] * n.z,
            a[0][2] * n.x + a[1][2] * n.y + a[2][2] * n.z};
}

bool Transform::flips_handedness() const {
    const auto &a = matrix.m;
    float det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    return det < 0;
}

bool Transform::preserves_lengths(float tolerance) const {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            float d = 0;
            for (int k = 0; k < 3; ++k) d += matrix.m[k][i] * matrix.m[k][j];
            if (std::abs(d - (i == j ? 1.f : 0.f)) >= tolerance) return false;
        }
    return true;
}

float uniform_scale(const Transform &to_world, const std::string &what) {
    Vec3 axes[3];
    float scale[3];
    for (int i = 0; i < 3; ++i) {
        axes[i] = to_world.vector(Vec3(i == 0, i == 1, i == 2));
        scale[i] = norm(axes[i]);
    }
    const float tol = 1e-4f * scale[0] * scale[0];
    if (std::abs(scale[1] - scale[0]) > 1e-4f * scale[0] || std::abs(scale[2] - scale[0]) > 1e-4f * scale[0] ||
        std::abs(dot(axes[0], axes[1])) > tol || std::abs(dot(axes[0], axes[2])) > tol || std::abs(dot(axes[1], axes[2])) > tol)
        throw std::runtime_error(what + " must scale uniformly (and not shear)");
    return scale[0];
}

}  // namespace neepp
