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

TEST(GridVolume, RefusesBadGrids) {
    VolumeGrid two = ramp();
    two.channels = 2;
    two.values.resize(4 * 2 * 2 * 2, 0.f);
    EXPECT_THROW(GridVolume(two, {}), std::invalid_argument);
    VolumeGrid negative = ramp();
    negative.values[3] = -1.f;
    EXPECT_THROW(GridVolume(negative, {}), std::invalid_argument);
    VolumeGrid nan = ramp();
    nan.values[5] = std::nanf("");
    EXPECT_THROW(GridVolume(nan, {}), std::invalid_argument);
}

TEST(ConstantVolume, IsDefinedOverTheUnitCubeItsToWorldPlaces) {
    const ConstantVolume v(Color(0.5f, 0.4f, 0.3f), Transform::translate(Vec3(-0.5f)));
    EXPECT_EQ(v.bounds().lo, Vec3(-0.5f));
    EXPECT_EQ(v.bounds().hi, Vec3(0.5f));
    EXPECT_FLOAT_EQ(v.max(), 0.5f);
    EXPECT_EQ(ConstantVolume(Color(1.f)).bounds().hi, Vec3(1.f));
}
