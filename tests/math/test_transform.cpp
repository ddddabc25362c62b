// Transform: inverses, rotation handedness, Mitsuba's lookat, normals under non-uniform scale, and
// orientation flips, lengths kept, inverse directions.
#include <gtest/gtest.h>

#include "neepp/math/transform.h"

namespace neepp::test {
namespace {

void expect_vec_near(const Vec3 &a, const Vec3 &b, float tol = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

void expect_identity(const Matrix4 &m, float tol = 1e-5f) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) EXPECT_NEAR(m.m[i][j], i == j ? 1.f : 0.f, tol) << "entry " << i << "," << j;
}

Transform composite() {
    return Transform::translate(Vec3(1, -2, 3)) * Transform::rotate(Vec3(1, 2, -0.5f), 33.f) *
           Transform::scale(Vec3(2, 0.5f, 3));
}

TEST(Transform, InverseUndoesTheTransform) {
    Transform t = composite();
    expect_identity(t.matrix * t.inverse_matrix);
    expect_identity(t.inverse().matrix * t.matrix);
    Vec3 p(0.3f, -1.7f, 2.2f);
    expect_vec_near(t.inverse().point(t.point(p)), p);
    expect_vec_near(t.inverse().vector(t.vector(p)), p);
    // The general inverse (used for <matrix> elements) agrees with the composed analytic inverses.
    Transform from_matrix(t.matrix);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) EXPECT_NEAR(from_matrix.inverse_matrix.m[i][j], t.inverse_matrix.m[i][j], 1e-5f);
    Matrix4 singular = Matrix4::identity();
    singular.m[2][2] = 0.f;
    EXPECT_THROW(singular.inverse(), std::runtime_error);
}

TEST(Transform, TranslationMovesPointsNotVectors) {
    Transform t = Transform::translate(Vec3(1, 2, 3));
    expect_vec_near(t.point(Vec3(1, 1, 1)), Vec3(2, 3, 4));
    expect_vec_near(t.vector(Vec3(1, 1, 1)), Vec3(1, 1, 1));
}

TEST(Transform, Rotate90DegreesIsRightHanded) {
    // Counter-clockwise looking down the axis: x -> y about z, y -> z about x, z -> x about y.
    expect_vec_near(Transform::rotate(Vec3(0, 0, 1), 90.f).vector(Vec3(1, 0, 0)), Vec3(0, 1, 0));
    expect_vec_near(Transform::rotate(Vec3(1, 0, 0), 90.f).vector(Vec3(0, 1, 0)), Vec3(0, 0, 1));
    expect_vec_near(Transform::rotate(Vec3(0, 1, 0), 90.f).vector(Vec3(0, 0, 1)), Vec3(1, 0, 0));
    expect_vec_near(Transform::rotate(Vec3(0, 1, 0), 90.f).vector(Vec3(1, 0, 0)), Vec3(0, 0, -1));
    // The axis itself is fixed, and the axis length does not matter.
    expect_vec_near(Transform::rotate(Vec3(0, 0, 5), 90.f).vector(Vec3(0, 0, 1)), Vec3(0, 0, 1));
    Transform r = Transform::rotate(Vec3(1, 1, 1), 120.f);  // cyclic permutation of the axes
    expect_vec_near(r.vector(Vec3(1, 0, 0)), Vec3(0, 1, 0));
    expect_identity(r.matrix * r.inverse_matrix);
}

TEST(Transform, LookAtMapsCameraFrameToView) {
    Vec3 eye(1, 2, 3), target(4, -1, 5), up(0, 1, 0);
    Transform t = Transform::look_at(eye, target, up);
    Vec3 dir = normalize(target - eye);
    expect_vec_near(t.point(Vec3(0, 0, 0)), eye);
    expect_vec_near(t.vector(Vec3(0, 0, 1)), dir);
    expect_vec_near(t.point(Vec3(0, 0, norm(target - eye))), target, 1e-4f);
    // Mitsuba's convention: camera +x is cross(up, dir) (left in the image), camera +y the up direction
    // made orthogonal to dir.
    expect_vec_near(t.vector(Vec3(1, 0, 0)), normalize(cross(up, dir)));
    Vec3 cam_up = t.vector(Vec3(0, 1, 0));
    EXPECT_NEAR(dot(cam_up, dir), 0.f, 1e-6f);
    EXPECT_GT(dot(cam_up, up), 0.f);
    EXPECT_FALSE(t.flips_handedness());
    expect_identity(t.matrix * t.inverse_matrix);
    EXPECT_THROW(Transform::look_at(eye, eye + up, up), std::runtime_error);
}

TEST(Transform, NormalsStayPerpendicularUnderNonUniformScale) {
    Transform t = Transform::rotate(Vec3(0.3f, 1, 0.2f), 40.f) * Transform::scale(Vec3(1, 4, 0.25f)) *
                  Transform::rotate(Vec3(1, 0, 0.5f), 25.f);
    Vec3 n = normalize(Vec3(1, 2, 3));
    Vec3 tangents[] = {normalize(cross(n, Vec3(1, 0, 0))), normalize(cross(n, Vec3(0, 1, 0)))};
    for (const Vec3 &tg : tangents) {
        ASSERT_NEAR(dot(n, tg), 0.f, 1e-6f);
        Vec3 tn = normalize(t.normal(n)), tt = normalize(t.vector(tg));
        EXPECT_NEAR(dot(tn, tt), 0.f, 1e-5f);
        // Transforming the normal as a vector would not stay perpendicular: this case exercises that.
        EXPECT_GT(std::abs(dot(normalize(t.vector(n)), tt)), 0.05f);
    }
}

TEST(Transform, FlipsHandedness) {
    EXPECT_FALSE(Transform().flips_handedness());
    EXPECT_FALSE(composite().flips_handedness());
    EXPECT_TRUE(Transform::scale(Vec3(-1, 1, 1)).flips_handedness());
    EXPECT_FALSE(Transform::scale(Vec3(-1, -1, 1)).flips_handedness());
    EXPECT_TRUE((composite() * Transform::scale(Vec3(1, 1, -2))).flips_handedness());
    // A translation in the last column does not enter the determinant of the linear part.
    EXPECT_FALSE(Transform::translate(Vec3(-5, -5, -5)).flips_handedness());
}

TEST(Transform, PreservesLengths) {
    EXPECT_TRUE(Transform().preserves_lengths());
    EXPECT_TRUE(Transform::rotate(Vec3(1, 2, -0.5f), 33.f).preserves_lengths());
    EXPECT_TRUE(Transform::look_at(Vec3(1, 2, 3), Vec3(0, 0, 0), Vec3(0, 1, 0)).preserves_lengths());
    EXPECT_TRUE((Transform::translate(Vec3(4, 5, 6)) * Transform::scale(Vec3(-1, 1, 1))).preserves_lengths());
    EXPECT_FALSE(composite().preserves_lengths());
    EXPECT_FALSE(Transform::scale(Vec3(1, 1, 1.01f)).preserves_lengths());
}

TEST(Transform, InverseVectorUndoesVector) {
    const Transform t = composite();
    const Vec3 v(0.3f, -1.2f, 2.f);
    expect_vec_near(t.inverse_vector(t.vector(v)), v);
    expect_vec_near(t.inverse_vector(v), t.inverse().vector(v));
}

}  // namespace
}  // namespace neepp::test
