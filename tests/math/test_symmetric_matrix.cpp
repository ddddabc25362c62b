// Symmetric 3x3 matrices (a 6-channel volume's value, SGGX's S): their eigenvalues against matrices built
// from known ones, the determinant and adjugate (det(S) S⁻¹).
#include <gtest/gtest.h>

#include <algorithm>

#include "neepp/math/frame.h"
#include "neepp/math/symmetric_matrix.h"

using namespace neepp;

namespace {

// R diag(a, b, c) Rᵀ for the rotation taking x, y, z to the frame's s, t, n.
SymmetricMatrix3 rotated(float a, float b, float c, const Frame &r) {
    auto outer = [](const Vec3 &x, float k) { return SymmetricMatrix3(k * x.x * x.x, k * x.y * x.y, k * x.z * x.z, k * x.x * x.y, k * x.x * x.z, k * x.y * x.z); };
    return outer(r.s, a) + outer(r.t, b) + outer(r.n, c);
}

}  // namespace

TEST(SymmetricMatrix3, EigenvaluesOfRotatedDiagonals) {
    const Frame r(normalize(Vec3(0.4f, 0.7f, -0.6f)));
    struct Case {
        float a, b, c;
    };
    for (const Case &k : {Case{1.f, 0.2f, 0.03f}, Case{1.f, 1.f, 0.01f}, Case{0.f, 0.f, 1.f}, Case{2.f, 2.f, 2.f}, Case{-1.f, 0.5f, 3.f}}) {
        const std::array<double, 3> e = eigenvalues(rotated(k.a, k.b, k.c, r));
        std::array<float, 3> want = {k.a, k.b, k.c};
        std::sort(want.begin(), want.end());
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(e[i], want[i], 2e-6) << k.a << " " << k.b << " " << k.c << " #" << i;
    }
    const std::array<double, 3> diagonal = eigenvalues(SymmetricMatrix3(3.f, -1.f, 2.f, 0.f, 0.f, 0.f));
    EXPECT_EQ(diagonal, (std::array<double, 3>{-1.0, 2.0, 3.0}));
}

TEST(SymmetricMatrix3, DeterminantAndAdjugate) {
    const SymmetricMatrix3 s(1.f, 0.35f, 0.32f, 0.52f, 0.44f, 0.2f);
    const SymmetricMatrix3 adj = s.adjugate();
    // S adj(S) = det(S) I, column by column.
    for (const Vec3 &e : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}) {
        const Vec3 col = s * (adj * e);
        for (int i = 0; i < 3; ++i) EXPECT_NEAR(col[i], e[i] * s.determinant(), 1e-6f);
    }
    EXPECT_NEAR(s.determinant(), 0.045094f * 0.137654f * 1.487252f, 1e-5f);  // the product of its eigenvalues
    EXPECT_FLOAT_EQ(s.form(Vec3(1, 0, 0), Vec3(0, 1, 0)), 0.52f);
}
