#include "neepp/visibility/transmittance.h"

#include <algorithm>
#include <cmath>
#include "neepp/base/shape.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/base/stats.h"

namespace neepp {
namespace {

// A segment's transmittance per channel: exactly for a homogeneous medium; else ratio tracking, free
// flights drawn in `channel` against the majorant, each tentative collision weighted by sigma_n / majorant
// (one density lookup each, counted in counters.transmittance_lookups).
Color segment_transmittance(const Medium &medium, const Ray &ray, float t_end, int channel, Sampler &sampler,
                            RenderCounters &counters, bool &crossed) {
    Ray r = ray;
    r.tmax = std::min(ray.tmax, t_end);
    float t0, t1;
    if (!medium.overlap(r, t0, t1)) return Color(1.f);
    crossed = true;
    const Color majorant = medium.majorant(ray.d);
    if (medium.homogeneous()) return vexp(-majorant * (t1 - t0));
    const float m = majorant[channel];
    if (!(m > 0)) return vexp(-majorant * (t1 - t0));
    Color T(1.f);
    for (float t = t0;;) {
        const float step = -std::log(1.f - sampler.next_1d()) / m;
        const float next = t + step;
        if (!(next < t1)) {
            // Past the end: what remains, over the density of getting there, per channel.
            const float rest = t1 - t;
            return T * vexp(-(majorant - Color(m)) * rest);
        }
        // A tentative collision, drawn with density m e^{-m step}: the ratio of its weight in each channel.
        ++counters.transmittance_lookups;
        T *= vexp(-(majorant - Color(m)) * step) * ((majorant - medium.at(r.at(next), ray.d).sigma_t) / m);
        if (!(max_component(T) > 0)) return Color(0.f);
        t = next;
    }
}

}  // namespace

Color trace_transmittance(const Scene &scene, const Ray &ray, const Medium *medium, int channel, Sampler &sampler,
                          RenderCounters &counters) {
    const uint64_t start = read_ticks();
    ++counters.shadow_rays;
    const bool bounded = ray.tmax < kInfinity;
    const Vec3 target = bounded ? ray.at(ray.tmax) : Vec3(0.f);
    Color T(1.f);
    bool crossed_medium = false;
    // First whether an opaque surface blocks the ray (one occlusion query); if none does, the ray is
    // walked through the surfaces that let light through, the media between them and their boundaries.
    auto done = [&](const Color &T) {
        counters.occlusion_ticks += read_ticks() - start;
        counters.shadow_rays_occluded += !(max_component(T) > 0);
        counters.medium_shadow_rays += crossed_medium;
        return T;
    };
    if (scene.occluded(ray, Scene::Surfaces::Opaque)) return done(Color(0.f));
    if (!scene.has_passable_surfaces())  // nothing else on the way, nothing that changes the medium
        return done(medium ? segment_transmittance(*medium, ray, ray.tmax, channel, sampler, counters, crossed_medium)
                           : Color(1.f));
    Ray r = ray;
    // Each surface crossed is one more query; a ray that would cross more than this many has let through
    // nothing worth the time (a stack of thin sheets).
    constexpr int kMaxCrossings = 256;
    for (int crossing = 0;; ++crossing) {
        if (crossing >= kMaxCrossings) {
            T = Color(0.f);
            break;
        }
        SurfaceInteraction si;
        const bool hit = scene.intersect(r, si, Scene::Surfaces::Passable);
        // What the surface ahead lets through, first: where it lets nothing through (a mask opaque there)
        // the segment's transmittance does not matter, and its ratio-tracking walk is not made.
        const Color through = hit ? si.shape->bsdf->null_transmission(si, si.wi) : Color(1.f);
        if (!(max_component(through) > 0)) {
            T = Color(0.f);
            break;
        }
        if (medium) T *= segment_transmittance(*medium, r, hit ? si.t : r.tmax, channel, sampler, counters, crossed_medium);
        if (!hit) break;
        T *= through;
        if (!(max_component(T) > 0)) break;
        if (si.shape->is_medium_transition()) medium = si.shape->medium_toward(r.d, si.n);
        // On past the surface, toward the same point.
        r = spawn_ray(si.p, si.n, r.d);
        if (bounded) r.tmax = dot(target - r.o, r.d);
        if (bounded && !(r.tmax > 0)) break;
    }
    return done(T);
}

Color test_transmittance(const ShadowRayTester &tester, const Scene &scene, const ShadowQuery &q, const Medium *medium,
                         int channel, Sampler &sampler, RenderCounters &counters) {
    const ShadowTest test = tester.begin_test(q, sampler, counters);
    if (!test.trace) return Color(test.if_skipped);
    const Color T = trace_transmittance(scene, q.ray, medium, channel, sampler, counters);
    // The map counts rays that got through: a fractional transmittance counts as through with its
    // probability, so the count's expectation is the expected transmittance.
    const float through = (T.x + T.y + T.z) * (1.f / 3.f);
    const bool visible = through >= 1.f || (through > 0.f && sampler.next_1d() < through);
    tester.end_test(test, !visible);
    return Color(test.if_occluded) + T * (test.if_visible - test.if_occluded);
}

}  // namespace neepp
