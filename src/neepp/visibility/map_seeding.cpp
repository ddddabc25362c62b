#include "neepp/visibility/map_seeding.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <stdexcept>
#include <tbb/parallel_for.h>
#include "neepp/math/denormals.h"
#include "neepp/math/frame.h"
#include "neepp/math/warp.h"
#include "neepp/media/free_flight.h"
#include "neepp/sampling/rng.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/transmittance.h"

namespace neepp {

namespace {

struct CellPoint {
    Vec3 p;
    // Surface points: the geometric normal on the side the path arrived from; points in a medium: 0; light
    // points: the light's normal (or 0).
    Vec3 n;
    const Medium *medium = nullptr;  // where shadow rays from the point start (on the side of n)
};

// Reservoir sampling of up to k items per cell, in a fixed insertion order with a fixed generator.
struct Reservoirs {
    int k;
    std::vector<std::vector<CellPoint>> items;
    std::vector<uint64_t> seen;
    PCG32 rng;
    Reservoirs(uint32_t cells, int k_, uint64_t seed) : k(k_), items(cells), seen(cells, 0), rng(seed, 7) {}
    void insert(uint32_t cell, const CellPoint &pt) {
        uint64_t s = ++seen[cell];
        if (items[cell].size() < size_t(k)) items[cell].push_back(pt);
        else if (uint64_t j = uint64_t(rng.next_float() * float(s)); j < uint64_t(k)) items[cell][j] = pt;
    }
};

// Shadow ray from surface point x (normal nx, facing the side rendering shades) toward y, stopping just
// short of it like SurfaceInteraction::spawn_ray_to; or toward direction d when y is at infinity.
Ray ray_between(const Vec3 &x, const Vec3 &nx, const Vec3 &target, bool infinite) {
    return infinite ? spawn_ray(x, nx, target) : spawn_ray_to(x, nx, target);
}

// 1. Camera pre-pass: each path writes its points into its own slots, so the result is independent of
//    scheduling; B slots per path, path_len[i] of them filled.
struct Prepass {
    int bounces = 1;
    std::vector<CellPoint> points;
    std::vector<uint8_t> len;
};

// The points of one pre-pass path in a scene without media: every surface it meets, leaving each by a
// cosine-sampled direction on the side it arrived from.
void surface_path(const Scene &scene, Ray ray, int B, Sampler &s, CellPoint *points, uint8_t &len) {
    for (int b = 0; b < B; ++b) {
        SurfaceInteraction si;
        if (!scene.intersect(ray, si)) break;
        Vec3 n = dot(si.n, ray.d) > 0 ? -si.n : si.n;  // the side the path arrived from
        points[b] = {si.p, n};
        len = uint8_t(b + 1);
        Vec3 d = Frame(n).to_world(square_to_cosine_hemisphere(s.next_2d()));
        ray = spawn_ray(si.p, n, d);
    }
}

// With media, where NEE happens also includes the points where paths scatter in them (a voxel inside fog
// may hold no surface at all). The path draws its distances by delta tracking, scatters in a medium
// toward a uniform direction, passes through surfaces that NEE never shades (a null boundary, a thin
// dielectric's transmission) and follows mirror-like ones as their BSDF samples them, keeping track of the
// medium it is in; each point keeps the medium its shadow rays start in.
void media_path(const Scene &scene, Ray ray, int B, Sampler &s, CellPoint *points, uint8_t &len) {
    const Medium *medium = scene.camera.medium;
    const int channel = std::min(int(s.next_1d() * 3.f), 2);
    SurfaceInteraction si;
    bool hit = false, need_hit = true;
    // Null collisions and crossings record nothing: a bound on them keeps a path in a dense
    // heterogeneous medium, or between two facing thin sheets, from running long.
    constexpr int kMaxEvents = 256;
    int b = 0;
    for (int event = 0; b < B && event < kMaxEvents; ++event) {
        if (need_hit) hit = scene.intersect(ray, si), need_hit = false;
        if (medium) {
            const FreeFlight flight = sample_free_flight(*medium, ray, hit ? si.t : ray.tmax, channel, s);
            if (flight.event == FreeFlight::Null) {
                ray.tmin = flight.t;
                continue;
            }
            if (flight.event == FreeFlight::Real) {
                const Vec3 p = ray.at(flight.t);
                points[b++] = {p, Vec3(0.f), medium};
                ray = Ray{p, square_to_uniform_sphere(s.next_2d()), 0.f, kInfinity};
                need_hit = true;
                continue;
            }
        }
        if (!hit) break;
        const Vec3 n = dot(si.n, ray.d) > 0 ? -si.n : si.n;  // the side the path arrived from
        Vec3 d;
        if (si.shape->bsdf_flags & BSDFSmooth) {
            const Medium *side = si.shape->is_medium_transition() ? si.shape->medium_toward(n, si.n) : medium;
            points[b++] = {si.p, n, side};
            d = Frame(n).to_world(square_to_cosine_hemisphere(s.next_2d()));
        } else {
            const float u1 = s.next_1d();
            const BSDFSample bs = si.shape->bsdf->sample(BSDFContext{}, si, si.wi, u1, s.next_2d());
            if (!bs.valid()) break;
            d = si.to_world(bs.wo);
        }
        if (si.shape->is_medium_transition()) medium = si.shape->medium_toward(d, si.n);
        ray = si.spawn_ray(d);
        need_hit = true;
    }
    len = uint8_t(b);
}

Prepass camera_prepass(const Scene &scene, const SeedingOptions &opt) {
    const int G = std::max(1, opt.camera_grid), B = std::max(1, opt.bounces);
    const size_t paths = size_t(G) * G;
    Prepass pre{B, std::vector<CellPoint>(paths * B), std::vector<uint8_t>(paths, 0)};
    const bool media = scene.has_media();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, paths, 256), [&](const tbb::blocked_range<size_t> &r) {
        const DenormalsAreZero ftz;
        IndependentSampler s(0);
        for (size_t i = r.begin(); i != r.end(); ++i) {
            s.start_stream(mix_bits(opt.seed ^ mix_bits(i)), 1);
            const float jx = s.next_1d(), jy = s.next_1d();
            const Vec2 film{(float(i % G) + jx) / float(G), (float(i / G) + jy) / float(G)};
            const Vec2 lens = scene.camera.has_lens() ? s.next_2d() : Vec2(0.5f, 0.5f);
            const Ray ray = scene.camera.generate_ray(film, lens);
            if (media) media_path(scene, ray, B, s, &pre.points[i * B], pre.len[i]);
            else surface_path(scene, ray, B, s, &pre.points[i * B], pre.len[i]);
        }
    });
    return pre;
}

}  // namespace

BBox shading_bounds(const Scene &scene, const SeedingOptions &opt) {
    const Prepass pre = camera_prepass(scene, opt);
    std::array<std::vector<float>, 3> axis;
    for (size_t i = 0; i < pre.len.size(); ++i)
        for (int b = 0; b < pre.len[i]; ++b)
            for (int k = 0; k < 3; ++k) axis[k].push_back(pre.points[i * pre.bounces + b].p[k]);
    const BBox all = scene.bounds();
    if (axis[0].size() < 100) return all;  // too few points to say where rendering happens
    BBox b;
    for (int k = 0; k < 3; ++k) {
        auto &v = axis[k];
        const size_t lo = v.size() / 100, hi = v.size() - 1 - v.size() / 100;
        std::nth_element(v.begin(), v.begin() + lo, v.end());
        b.lo[k] = std::max(v[lo], all.lo[k]);
        std::nth_element(v.begin(), v.begin() + hi, v.end());
        b.hi[k] = std::min(v[hi], all.hi[k]);
        if (!(b.hi[k] > b.lo[k])) b.lo[k] = all.lo[k], b.hi[k] = all.hi[k];  // a flat spread: the scene's extent
    }
    return b;
}

SeedingStats seed_visibility_map(const Scene &scene, const VoxelGrid &grid, VisibilityMap &map,
                                 const SeedingOptions &opt) {
    if (map.cell_count() != grid.cell_count()) throw std::invalid_argument("seed_visibility_map: map/grid mismatch");
    if (opt.samples_per_pair < 1) throw std::invalid_argument("samples_per_pair must be >= 1");
    auto t0 = std::chrono::steady_clock::now();
    SeedingStats stats;
    const uint32_t cells = grid.cell_count();

    const Prepass pre = camera_prepass(scene, opt);
    const size_t paths = pre.len.size();
    const int B = pre.bounces;
    const std::vector<CellPoint> &path_points = pre.points;
    const std::vector<uint8_t> &path_len = pre.len;
    for (size_t i = 0; i < paths; ++i) stats.camera_rays += std::min<uint64_t>(uint64_t(path_len[i]) + 1, uint64_t(B));
    Reservoirs surface(cells, opt.points_per_voxel, opt.seed + 1);
    std::vector<CellPoint> all_points;
    for (size_t i = 0; i < paths; ++i)
        for (int b = 0; b < path_len[i]; ++b) {
            const CellPoint &pt = path_points[i * B + b];
            surface.insert(grid.voxel_of(pt.p), pt);
            all_points.push_back(pt);
        }
    std::vector<uint32_t> shading_cells;
    for (uint32_t c = 0; c < grid.voxel_count(); ++c)
        if (!surface.items[c].empty()) shading_cells.push_back(c);
    stats.occupied_voxels = shading_cells.size();

    // 2. Light ends, sampled as NEE samples them from the recorded shading points. Light points keep the
    //    light's normal; environment samples keep their direction (in p) and a zero normal.
    Reservoirs light_ends(cells, opt.points_per_voxel, opt.seed + 2);
    if (!all_points.empty()) {
        PCG32 rng(opt.seed + 3, 3);
        const size_t n_lights = std::max<size_t>(1, scene.lights().size());
        const int per_light = int(std::min<size_t>(size_t(opt.light_samples_per_light), std::max<size_t>(256, (size_t(1) << 18) / n_lights)));
        for (const auto &light : scene.lights())
            for (int s = 0; s < per_light; ++s) {
                const CellPoint &ref = all_points[std::min(all_points.size() - 1, size_t(rng.next_float() * float(all_points.size())))];
                Color Le;
                DirectionSample ds = light->sample_direction(ref.p, rng.next_2d(), Le);
                if (is_black(Le) || !(ds.pdf > 0)) continue;
                if (ds.dist >= kInfinity) light_ends.insert(grid.cell_of_direction(ds.d), {ds.d, Vec3(0.f)});
                else light_ends.insert(grid.voxel_of(ds.p), {ds.p, ds.n});
            }
    }
    std::vector<uint32_t> light_cells;
    for (uint32_t c = 0; c < cells; ++c)
        if (!light_ends.items[c].empty()) light_cells.push_back(c);
    stats.light_cells = light_cells.size();

    // 3. Explicit samples per (shading voxel, light cell) pair. Same-voxel pairs are skipped: the
    //    policies always trace them. Samples whose direction lies behind the shading point's surface, or
    //    that reach an area light from its back, are not traced: NEE never asks for them (the BSDF or the
    //    emission is zero there), and counting them would bias the pair's estimate toward their outcome.
    const bool media = scene.has_media();
    struct PairJob { uint32_t a, b; };
    std::vector<PairJob> jobs;
    for (uint32_t a : shading_cells)
        for (uint32_t b : light_cells)
            if (a != b) jobs.push_back({a, b});
    std::vector<PairCounts> results(jobs.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, jobs.size(), 16), [&](const tbb::blocked_range<size_t> &r) {
        const DenormalsAreZero ftz;
        for (size_t j = r.begin(); j != r.end(); ++j) {
            const auto &xs = surface.items[jobs[j].a];
            const auto &ys = light_ends.items[jobs[j].b];
            const bool infinite = grid.is_direction_cell(jobs[j].b);
            PCG32 rng(mix_bits(opt.seed ^ mix_bits((uint64_t(jobs[j].a) << 32) | jobs[j].b)), 5);
            IndependentSampler tracking(0);  // for the free flights of transmittance estimates
            if (media) tracking.start_stream(rng.next_u32(), 6);
            uint32_t visible = 0, traced = 0;
            float through = 0.f;  // with media: the sum of the traced rays' transmittances
            for (int s = 0; s < opt.samples_per_pair; ++s) {
                const CellPoint &x = xs[std::min(xs.size() - 1, size_t(rng.next_float() * float(xs.size())))];
                const CellPoint &y = ys[std::min(ys.size() - 1, size_t(rng.next_float() * float(ys.size())))];
                Vec3 d = infinite ? y.p : y.p - x.p;
                const bool on_surface = squared_norm(x.n) > 0;
                if (on_surface && dot(d, x.n) <= 0) continue;
                if (!infinite && dot(y.n, d) >= 0 && squared_norm(y.n) > 0) continue;
                ++traced;
                if (!media) {
                    visible += !scene.occluded(ray_between(x.p, x.n, y.p, infinite));
                    continue;
                }
                Ray ray;
                if (on_surface) ray = ray_between(x.p, x.n, y.p, infinite);
                else if (infinite) ray = Ray{x.p, d, 0.f, kInfinity};
                else {
                    const float dist = norm(d);
                    if (!(dist > 0)) continue;
                    ray = Ray{x.p, d / dist, 0.f, dist * (1.f - kShadowEpsilon)};
                }
                RenderCounters ignored;
                const Color T = trace_transmittance(scene, ray, x.medium, s % 3, tracking, ignored);
                through += (T.x + T.y + T.z) * (1.f / 3.f);
            }
            // The map counts rays that got through; with media, the sum of transmittances rounded up or down
            // at random in proportion, so that the count's expectation is the expected transmittance's.
            if (media) {
                const float whole = std::floor(through);
                visible = uint32_t(whole) + (rng.next_float() < through - whole);
                visible = std::min(visible, traced);
            }
            results[j] = {uint16_t(visible), uint16_t(traced)};
        }
    });
    for (size_t j = 0; j < jobs.size(); ++j) {
        if (!results[j].traced) continue;
        map.add(jobs[j].a, jobs[j].b, results[j].visible, results[j].traced);
        stats.shadow_rays += results[j].traced;
        ++stats.seeded_pairs;
    }
    stats.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return stats;
}

}  // namespace neepp
