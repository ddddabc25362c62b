// The grid NEE++ keys its map by: linear voxel indices, clamping outside points, direction bins.
#include <gtest/gtest.h>
#include "neepp/sampling/rng.h"
#include "neepp/math/warp.h"
#include "neepp/visibility/voxel_grid.h"

using namespace neepp;

namespace {

BBox unit_box() {
    BBox b;
    b.lo = Vec3(0.f);
    b.hi = Vec3(1.f);
    return b;
}

TEST(VoxelGrid, LinearIndexOfCellCenters) {
    VoxelGrid g = VoxelGrid::with_exact_bounds(unit_box(), 4);
    EXPECT_EQ(g.voxel_count(), 64u);
    EXPECT_EQ(g.cell_count(), 64u + uint32_t(VoxelGrid::kDirectionBins));
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 4; ++x) {
                Vec3 p((x + 0.5f) / 4, (y + 0.5f) / 4, (z + 0.5f) / 4);
                uint32_t c = g.voxel_of(p);
                EXPECT_EQ(c, uint32_t(x + 4 * (y + 4 * z)));
                int cx, cy, cz;
                g.voxel_coords(c, cx, cy, cz);
                EXPECT_EQ(cx, x); EXPECT_EQ(cy, y); EXPECT_EQ(cz, z);
                EXPECT_FALSE(g.is_direction_cell(c));
            }
}

TEST(VoxelGrid, OutsidePointsClampAndNanIsSafe) {
    VoxelGrid g = VoxelGrid::with_exact_bounds(unit_box(), 4);
    EXPECT_EQ(g.voxel_of(Vec3(-5, -5, -5)), 0u);
    EXPECT_EQ(g.voxel_of(Vec3(5, 5, 5)), 63u);
    EXPECT_EQ(g.voxel_of(Vec3(1, 1, 1)), 63u);  // the upper boundary belongs to the last voxel
    EXPECT_EQ(g.voxel_of(Vec3(5, -1, 0.3f)), uint32_t(3 + 4 * (0 + 4 * 1)));
    EXPECT_LT(g.voxel_of(Vec3(std::nanf(""), 0.5f, 0.5f)), g.voxel_count());
}

TEST(VoxelGrid, EnlargesSceneBoundsSoBoundaryPointsAreInside) {
    VoxelGrid g(unit_box(), 16);
    EXPECT_LT(g.bounds().lo.x, 0.f);
    EXPECT_GT(g.bounds().hi.y, 1.f);
    EXPECT_THROW(VoxelGrid(unit_box(), 0), std::invalid_argument);
    EXPECT_THROW(VoxelGrid(unit_box(), 33), std::invalid_argument);
    BBox flat = unit_box();
    flat.hi.y = 0;  // a single quad: zero extent along y must still give a valid grid
    EXPECT_NO_THROW(VoxelGrid(flat, 16));
}

TEST(VoxelGrid, DirectionBinsCoverTheSphereAndRoundTrip) {
    VoxelGrid g(unit_box(), 8);
    std::vector<int> hits(VoxelGrid::kDirectionBins, 0);
    PCG32 rng(1, 2);
    for (int i = 0; i < 20000; ++i) {
        uint32_t c = g.cell_of_direction(square_to_uniform_sphere(rng.next_2d()));
        ASSERT_TRUE(g.is_direction_cell(c));
        ASSERT_LT(c, g.cell_count());
        ++hits[c - g.voxel_count()];
    }
    for (int b = 0; b < VoxelGrid::kDirectionBins; ++b) EXPECT_GT(hits[b], 0) << "bin " << b;
    for (uint32_t c = g.voxel_count(); c < g.cell_count(); ++c)
        for (int k = 0; k < 8; ++k) {
            Vec3 d = g.direction_in_bin(c, {0.05f + 0.9f * rng.next_float(), 0.05f + 0.9f * rng.next_float()});
            EXPECT_NEAR(norm(d), 1.f, 1e-5f);
            EXPECT_EQ(g.cell_of_direction(d), c);
        }
    // Opposite directions are in different bins.
    EXPECT_NE(g.cell_of_direction(Vec3(0, 1, 0)), g.cell_of_direction(Vec3(0, -1, 0)));
}

}  // namespace
