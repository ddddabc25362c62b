// Mitsuba's volumes: a gridvolume's lookups (texel centres, trilinear weights, the wrap modes, nearest
// filtering, to_world and use_grid_bbox), its max and bounds, and bad grids refused.
#include <gtest/gtest.h>

#include "neepp/media/volume.h"

using namespace neepp;

namespace {

// 4 x 2 x 2 texels, one channel: value = x + 10 y + 100 z, so every lookup says where it read.
VolumeGrid ramp(int channels = 1) {
    VolumeGrid g;
    g.size[0] = 4, g.size[1] = 2, g.size[2] = 2;
    g.channels = uint32_t(channels);
    g.bounds = BBox{Vec3(-1.f), Vec3(3.f)};
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 4; ++x)
                for (int c = 0; c < channels; ++c) g.values.push_back(float(x + 10 * y + 100 * z + 1000 * c));
    return g;
}

// The point of the unit cube at texel coordinates (x, y, z) (texel centres at integers).
Vec3 at_texel(float x, float y, float z) { return Vec3((x + 0.5f) / 4.f, (y + 0.5f) / 2.f, (z + 0.5f) / 2.f); }

}  // namespace

TEST(GridVolume, TexelCentresTrilinearWeightsAndChannels) {
    const GridVolume v(ramp(), {});
    EXPECT_FLOAT_EQ(v.eval(at_texel(2, 1, 0)).x, 12.f);
    EXPECT_FLOAT_EQ(v.eval(at_texel(1.25f, 0.5f, 0.75f)).y, 1.25f + 5.f + 75.f);  // linear: the weights show
    EXPECT_FLOAT_EQ(v.max(), 113.f);
    const GridVolume rgb(ramp(3), {});
    const Color c = rgb.eval(at_texel(1, 1, 1));
    EXPECT_FLOAT_EQ(c.x, 111.f);
    EXPECT_FLOAT_EQ(c.y, 1111.f);
    EXPECT_FLOAT_EQ(c.z, 2111.f);
    EXPECT_FLOAT_EQ(rgb.max(), 2113.f);
}

TEST(GridVolume, WrapModesAndNearest) {
    GridVolumeOptions o;
    // Clamp (the default): past the last centre the value stays the edge texel's.
    EXPECT_FLOAT_EQ(GridVolume(ramp(), o).eval(at_texel(3.4f, 0, 0)).x, 3.f);
    EXPECT_FLOAT_EQ(GridVolume(ramp(), o).eval(at_texel(-0.4f, 0, 0)).x, 0.f);
    // Repeat: halfway between the last texel and the first.
    o.wrap = GridVolumeOptions::Wrap::Repeat;
    EXPECT_FLOAT_EQ(GridVolume(ramp(), o).eval(at_texel(3.5f, 0, 0)).x, 1.5f);
    // Mirror: past the end the texels come back in reverse, the edge one twice.
    o.wrap = GridVolumeOptions::Wrap::Mirror;
    EXPECT_FLOAT_EQ(GridVolume(ramp(), o).eval(at_texel(4.f, 0, 0)).x, 3.f);
    EXPECT_FLOAT_EQ(GridVolume(ramp(), o).eval(at_texel(5.f, 0, 0)).x, 2.f);
    o.wrap = GridVolumeOptions::Wrap::Clamp;
    o.filter = GridVolumeOptions::Filter::Nearest;
    EXPECT_FLOAT_EQ(GridVolume(ramp(), o).eval(at_texel(1.45f, 0.4f, 0.4f)).x, 1.f);
    EXPECT_FLOAT_EQ(GridVolume(ramp(), o).eval(at_texel(1.55f, 0.6f, 0.4f)).x, 12.f);
}

TEST(GridVolume, ToWorldAndGridBoundsPlaceIt) {
    GridVolumeOptions o;
    o.to_world = Transform::translate(Vec3(1.f, 0.f, 0.f)) * Transform::scale(Vec3(2.f));
    const GridVolume v(ramp(), o);
    EXPECT_FLOAT_EQ(v.eval(Vec3(1.f, 0.f, 0.f) + at_texel(2, 1, 0) * 2.f).x, 12.f);
    EXPECT_EQ(v.bounds().lo, Vec3(1.f, 0.f, 0.f));
    EXPECT_EQ(v.bounds().hi, Vec3(3.f, 2.f, 2.f));
    // use_grid_bbox: the file's bounds [-1, 3]^3 are what to_world (here the identity) places.
    GridVolumeOptions b;
    b.use_grid_bbox = true;
    const GridVolume w(ramp(), b);
    EXPECT_FLOAT_EQ(w.eval(Vec3(-1.f) + at_texel(2, 1, 0) * 4.f).x, 12.f);
    EXPECT_EQ(w.bounds().lo, Vec3(-1.f));
    EXPECT_EQ(w.bounds().hi, Vec3(3.f));
}

// Each refusal says what is wrong and where in the grid (x fastest, then y, then z), so that the file's
// writer can find it; the loader adds the file and the scene's line.
TEST(GridVolume, RefusesBadGridsSayingWhere) {
    auto message = [](const VolumeGrid &g, const GridVolumeOptions &o = {}) -> std::string {
        try {
            GridVolume v(g, o);
        } catch (const std::invalid_argument &e) {
            return e.what();
        }
        return "";
    };
    auto contains = [](const std::string &msg, const std::string &needle) { return msg.find(needle) != std::string::npos; };
    for (int channels : {2, 4, 5, 7}) {
        VolumeGrid g = ramp();
        g.channels = uint32_t(channels);
        g.values.resize(4 * 2 * 2 * size_t(channels), 0.f);
        const std::string msg = message(g);
        EXPECT_TRUE(contains(msg, "has " + std::to_string(channels) +
                                      " channels; a gridvolume's value is grey (1 channel), RGB (3) or a symmetric matrix (6"))
            << msg;
    }
    VolumeGrid negative = ramp();
    negative.values[3] = -1.f;  // x = 3, y = 0, z = 0
    EXPECT_TRUE(contains(message(negative), "grid point (3, 0, 0) is -1.000000: a gridvolume's values")) << message(negative);
    EXPECT_TRUE(contains(message(negative), "are not negative")) << message(negative);
    VolumeGrid nan = ramp();
    nan.values[4 + 2 + 8] = std::nanf("");  // x = 2, y = 1, z = 1
    EXPECT_TRUE(contains(message(nan), "grid point (2, 1, 1) is nan: not a finite number")) << message(nan);
    VolumeGrid inf = ramp(3);
    inf.values[3 * 5 + 2] = -INFINITY;  // point 5 (x = 1, y = 1), channel 2
    EXPECT_TRUE(contains(message(inf), "grid point (1, 1, 0), channel 2, is -inf: not a finite number")) << message(inf);
    // A max_value below the data cannot bound it: free flights drawn against it would be biased. One above
    // it is Mitsuba's conservative bound.
    GridVolumeOptions low;
    low.max_value = 100.f;
    EXPECT_TRUE(contains(message(ramp(), low), "max_value 100.000000 is below the grid's largest value 113.000000")) << message(ramp(), low);
    GridVolumeOptions high;
    high.max_value = 200.f;
    EXPECT_FLOAT_EQ(GridVolume(ramp(), high).max(), 200.f);
    // use_grid_bbox on stored bounds that are no box.
    GridVolumeOptions bbox;
    bbox.use_grid_bbox = true;
    for (const BBox &b : {BBox{Vec3(0.f), Vec3(INFINITY)}, BBox{Vec3(0.f), Vec3(0.f)}, BBox{Vec3(NAN), Vec3(1.f)}}) {
        VolumeGrid g = ramp();
        g.bounds = b;
        EXPECT_TRUE(contains(message(g, bbox), "use_grid_bbox: the grid's stored bounds are not a finite box")) << message(g, bbox);
    }
}

TEST(ConstantVolume, IsDefinedOverTheUnitCubeItsToWorldPlaces) {
    const ConstantVolume v(Color(0.5f, 0.4f, 0.3f), Transform::translate(Vec3(-0.5f)));
    EXPECT_EQ(v.bounds().lo, Vec3(-0.5f));
    EXPECT_EQ(v.bounds().hi, Vec3(0.5f));
    EXPECT_FLOAT_EQ(v.max(), 0.5f);
    EXPECT_EQ(ConstantVolume(Color(1.f)).bounds().hi, Vec3(1.f));
}

// Six channels: a symmetric matrix at each point (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz, an sggx phase
// function's S), each entry interpolated as a colour's channels; its max the largest eigenvalue anywhere.
TEST(GridVolume, SixChannelsAreSymmetricMatrices) {
    VolumeGrid g;
    g.size[0] = 2, g.size[1] = 1, g.size[2] = 1, g.channels = 6;
    // diag(1, 1, 0.01), then a rotated matrix with negative entries off the diagonal (eigenvalues 3, 1, 1).
    g.values = {1.f, 1.f, 0.01f, 0.f, 0.f, 0.f, 5.f / 3.f, 5.f / 3.f, 5.f / 3.f, -2.f / 3.f, -2.f / 3.f, 2.f / 3.f};
    const GridVolume v(g, {});
    EXPECT_EQ(v.channels(), 6);
    EXPECT_FALSE(v.uniform());
    EXPECT_NEAR(v.max(), 3.f, 1e-5f);
    const SymmetricMatrix3 a = v.eval_matrix(Vec3(0.1f, 0.5f, 0.5f)), mid = v.eval_matrix(Vec3(0.5f, 0.5f, 0.5f));
    EXPECT_EQ(a, SymmetricMatrix3(1.f, 1.f, 0.01f, 0.f, 0.f, 0.f));
    EXPECT_FLOAT_EQ(mid.zz, (0.01f + 5.f / 3.f) / 2);
    EXPECT_FLOAT_EQ(mid.xz, -1.f / 3.f);
    EXPECT_FLOAT_EQ(mid.yz, 1.f / 3.f);
    GridVolumeOptions nearest;
    nearest.filter = GridVolumeOptions::Filter::Nearest;
    EXPECT_FLOAT_EQ(GridVolume(g, nearest).eval_matrix(Vec3(0.6f, 0.5f, 0.5f)).xy, -2.f / 3.f);
    // Every point the same matrix: uniform (a homogeneous medium may take its S from such a grid).
    VolumeGrid same = g;
    std::copy(g.values.begin(), g.values.begin() + 6, same.values.begin() + 6);
    EXPECT_TRUE(GridVolume(same, {}).uniform());
    EXPECT_FALSE(GridVolume(ramp(), {}).uniform());
    // A matrix that is not positive semi-definite (an eigenvalue of -1), or not finite, is refused where it is.
    auto message = [](const VolumeGrid &grid) -> std::string {
        try {
            GridVolume bad(grid, {});
        } catch (const std::invalid_argument &e) {
            return e.what();
        }
        return "";
    };
    VolumeGrid indefinite = g;
    indefinite.values[6 + 3] = 2.f + 5.f / 3.f;  // point (1, 0, 0): S_xy too large for its diagonal
    EXPECT_NE(message(indefinite).find("the matrix (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz) at grid point (1, 0, 0) has an eigenvalue of -"),
              std::string::npos)
        << message(indefinite);
    EXPECT_NE(message(indefinite).find("not positive semi-definite"), std::string::npos) << message(indefinite);
    VolumeGrid nan = g;
    nan.values[4] = NAN;
    EXPECT_NE(message(nan).find("at grid point (0, 0, 0) holds nan: not a finite number"), std::string::npos) << message(nan);
}

TEST(ConstantVolume, SixValuesAreAMatrix) {
    const ConstantVolume v(SymmetricMatrix3(0.5f, 0.25f, 2.f, 0.f, 0.f, 0.f));
    EXPECT_EQ(v.channels(), 6);
    EXPECT_FLOAT_EQ(v.max(), 2.f);
    EXPECT_EQ(v.eval_matrix(Vec3(3.f)), SymmetricMatrix3(0.5f, 0.25f, 2.f, 0.f, 0.f, 0.f));
    EXPECT_EQ(ConstantVolume(Color(0.2f)).channels(), 3);
}
