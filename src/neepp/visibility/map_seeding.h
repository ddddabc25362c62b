// Seeding the visibility map before rendering with explicit visibility samples between points that
// rendering itself finds (the paper: 16 samples per voxel pair suffice, 64 are no better):
//  1. a short pre-pass of camera paths (a jittered grid of film positions, a few cosine-sampled diffuse
//     bounces) keeps a small reservoir of surface points per voxel: the shading points NEE will query;
//  2. each light is sampled from those points with Light::sample_direction, exactly as NEE samples it,
//     keeping reservoirs of light points per voxel (or of directions per direction bin for environment
//     lights): the other ends of the shadow rays NEE will trace;
//  3. for every (occupied shading voxel, light cell) pair, samples_per_pair shadow rays are traced
//     between random stored points of the two cells and their outcomes become the pair's counts.
// With participating media, step 1 also records where paths scatter in them, and the samples of step 3
// are transmittances through media and the surfaces that let light through: the map then holds expected
// transmittance, what NEE++ learns from rendering's shadow rays in such scenes.
// Everything is drawn from fixed per-path / per-pair seeds, so the map is the same on any thread count.
#pragma once
#include <cstdint>
#include "neepp/visibility/visibility_map.h"
#include "neepp/visibility/voxel_grid.h"

namespace neepp {

class Scene;

struct SeedingOptions {
    int samples_per_pair = 16;
    int camera_grid = 128;        // camera_grid² pre-pass paths
    int bounces = 4;              // surface points recorded per path, at most
    int points_per_voxel = 16;    // reservoir size per shading voxel and per light cell
    // Light samples per light, scaled down for scenes with many lights (at most ~262k in all, at least
    // 256 each): enough to fill every light voxel's reservoir without making seeding scale with lights².
    int light_samples_per_light = 16384;
    uint64_t seed = 0x6e65657070ULL;
};

struct SeedingStats {
    double time_s = 0;
    uint64_t camera_rays = 0;      // closest-hit queries of the pre-pass
    uint64_t shadow_rays = 0;      // explicit visibility samples traced into the map
    uint64_t occupied_voxels = 0;  // voxels holding pre-pass points (on surfaces or in media)
    uint64_t light_cells = 0;      // voxels holding light points plus direction bins holding directions
    uint64_t seeded_pairs = 0;     // pairs that received at least one sample
};

// Where rendering shades: the bounds of the pre-pass's surface points (step 1), each axis cut at its 1st
// and 99th percentile so that a few far points (a ground plane seen through a window) do not set them,
// within the scene's bounds. A grid over them spends its voxels where the shading points are; points
// outside fall in its boundary voxels.
BBox shading_bounds(const Scene &scene, const SeedingOptions &options);

// Adds the explicit samples to map (which must have grid.cell_count() cells).
SeedingStats seed_visibility_map(const Scene &scene, const VoxelGrid &grid, VisibilityMap &map, const SeedingOptions &options);

}  // namespace neepp
