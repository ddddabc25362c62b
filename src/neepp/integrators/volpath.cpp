// The volumetric path tracer (Mitsuba 3's volpath), the reference form: one path, one event at a time.
//
// An event is where the path meets something: a collision in a medium (real, where light scatters, or
// null, a fiction that lets a heterogeneous medium be sampled against a bound on its density), or a
// surface. Real collisions and surfaces that scatter are the path's vertices, counted by max_depth as
// Mitsuba counts them; null collisions and surfaces the path passes straight through (null, a mask's
// clear part, a thin dielectric's transmission) are not.
//
// In RGB, media may attenuate the channels differently. One channel, drawn once per path (the hero), drives
// every distance the path and its shadow rays sample; the path's weight is its contribution over the mean
// of the densities each channel would have given it (Mitsuba's volpathmis, one-sample MIS over channels).
#include <algorithm>
#include <cmath>
#include <optional>

#include "neepp/base/bsdf.h"
#include "neepp/base/medium.h"
#include "neepp/integrators/path.h"
#include "neepp/math/warp.h"
#include "neepp/media/free_flight.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/transmittance.h"

namespace neepp {

// Where a path scatters: a surface (si, its BSDF) or a point in a medium (its phase function).
struct PathIntegrator::ScatteringPoint {
    const SurfaceInteraction *si = nullptr;  // null in a medium
    Vec3 p, wi;                              // the point, and (world) the direction back along the path
    const Medium *medium = nullptr;          // the medium the path is in there
    LightSampleContext ctx;
};

Color PathIntegrator::sample_direct_volumetric(const Scene &scene, const ScatteringPoint &v, const Color &beta,
                                               int channel, Sampler &sampler, RenderCounters &counters) const {
    const SampledLight chosen = light_sampler_->sample(v.ctx, sampler.next_1d());
    const Vec2 u = sampler.next_2d();
    if (!chosen.light || !(chosen.pmf > 0)) return Color(0.f);
    const ContextLightSampler *within = within_light_.for_light(*chosen.light);
    Color Le(0.f);
    const DirectionSample ds = within ? within->sample(v.ctx, u, Le) : chosen.light->sample_direction(v.p, u, Le);
    if (!(ds.pdf > 0) || is_black(Le)) return Color(0.f);
    // What the surface or the medium scatters toward the light, and the density of sampling that way.
    Color f;
    float scatter_pdf;
    const Medium *medium = v.medium;
    ShadowQuery q;
    if (v.si) {
        const SurfaceInteraction &si = *v.si;
        const BSDFEval e = si.shape->bsdf->eval_pdf(BSDFContext{}, si, si.wi, si.to_local(ds.d));
        f = e.f, scatter_pdf = e.pdf;
        q.ray = ds.dist >= kInfinity ? si.spawn_ray(ds.d) : si.spawn_ray_to(ds.p);
        if (si.shape->is_medium_transition()) medium = si.shape->medium_toward(ds.d, si.n);
    } else {
        const PhaseFunction &phase = *v.medium->phase;
        f = Color(phase.eval(v.p, v.wi, ds.d));
        scatter_pdf = phase.pdf(v.p, v.wi, ds.d);
        q.ray = Ray{v.p, ds.d, 0.f, ds.dist >= kInfinity ? kInfinity : ds.dist * (1.f - kShadowEpsilon)};
    }
    if (is_black(f)) return Color(0.f);
    const float light_pdf = ds.pdf * chosen.pmf;
    const float w_mis = ds.delta ? 1.f : mis_power(light_pdf, scatter_pdf);
    q.from = v.p;
    q.to = ds.p;
    q.unoccluded = beta * f * Le * (w_mis / light_pdf);
    return q.unoccluded * test_transmittance(*queries_, scene, q, medium, channel, sampler, counters);
}

Color PathIntegrator::Li_volumetric(const Scene &scene, const Ray &camera_ray, Sampler &sampler,
                                    RenderCounters &counters) const {
    Color L(0.f), beta(1.f);  // radiance so far, and the path throughput up to the current event
    float eta = 1.f;          // product of relative IORs crossed, for Russian roulette
    Ray ray = camera_ray;
    const Medium *medium = scene.camera.medium;
    const int channel = scene.has_media() ? std::min(int(sampler.next_1d() * 3.f), 2) : 0;
    // The path's density had each channel drawn its distances, over their mean (Mitsuba's volpathmis): the
    // throughput is f over that mean, one-sample MIS between the channels by the balance heuristic, so that
    // a channel the hero samples badly (a chromatic medium) does not carry huge weights.
    Color pdf_ratio(1.f);
    int depth = 0;  // scattering vertices so far: collisions in media and surfaces that are not null
    // The last scattering vertex, for the MIS weight of emission that a ray sampled there finds (null
    // events in between change neither it nor its density).
    LightSampleContext prev;
    float prev_pdf = 1.f;
    bool prev_delta = true;  // the camera, a delta lobe, or a medium that samples no lights: no MIS
    const bool bounded = options_.max_depth >= 0;
    SurfaceInteraction si;
    bool hit = false, need_hit = true;
    for (;;) {
        // In a homogeneous medium where the path collides does not depend on what lies beyond: the distance
        // is drawn first and surfaces are looked for only up to it (as Mitsuba does). In a dense medium most
        // rays then end before any surface, and a short query that finds nothing is cheap.
        std::optional<FreeFlight> drawn_first;
        if (need_hit) {
            Ray query = ray;
            if (medium && medium->homogeneous()) {
                drawn_first = sample_free_flight(*medium, ray, ray.tmax, channel, sampler);
                if (drawn_first->event != FreeFlight::Passed) query.tmax = drawn_first->t;
            }
            hit = scene.intersect(query, si);
            ++counters.rays;
            need_hit = false;
        }
        // In a medium: a collision before the surface ahead, or none.
        if (medium) {
            FreeFlight flight = drawn_first ? *drawn_first : sample_free_flight(*medium, ray, hit ? si.t : ray.tmax, channel, sampler);
            if (drawn_first && hit) flight = passed_free_flight(*medium, ray, si.t);  // the surface came first
            counters.density_lookups += flight.event != FreeFlight::Passed;
            const Color p = pdf_ratio * flight.pdf;
            const float mean = (p.x + p.y + p.z) / 3.f;
            if (!(mean > 0)) break;
            beta *= flight.f / mean;
            pdf_ratio = p / mean;
            if (!(max_component(beta) > 0)) break;  // absorbed (an albedo of 0)
            if (flight.event == FreeFlight::Null) {  // on along the same ray, toward the same surface
                ray.tmin = flight.t;
                continue;
            }
            if (flight.event == FreeFlight::Real) {
                if (bounded && depth + 1 >= options_.max_depth) break;
                ScatteringPoint v;
                v.p = ray.at(flight.t);
                v.wi = -ray.d;
                v.medium = medium;
                v.ctx = LightSampleContext{v.p, Vec3(0.f)};
                if (options_.nee && medium->sample_emitters)
                    L += sample_direct_volumetric(scene, v, beta, channel, sampler, counters);
                const PhaseSample ps = medium->phase->sample(v.p, v.wi, sampler.next_2d());
                if (!(ps.pdf > 0)) break;
                beta *= Color(ps.weight);
                ++depth;
                prev = v.ctx;
                prev_pdf = ps.pdf;
                prev_delta = !medium->sample_emitters;
                ray = Ray{v.p, ps.wo, 0.f, kInfinity};
                need_hit = true;
                if (depth > options_.rr_depth && !survives_roulette(beta, eta, sampler)) break;
                if (!(max_component(beta) > 0)) break;
                continue;
            }
        }

        // The surface ahead, or nothing: emission along the ray, as the surface path tracer adds it.
        const bool show_emission = depth > 0 || !options_.hide_emitters;
        if (!hit) {
            if (show_emission)
                for (const Light *env : scene.infinite_lights()) {
                    const Color Le = env->eval_environment(ray.d);
                    if (is_black(Le)) continue;
                    const float w = prev_delta ? 1.f : emission_weight(*env, prev, direction_sample_from_miss(ray.d), prev_pdf);
                    L += beta * Le * w;
                }
            break;
        }
        if (const Light *area = si.shape->area_light; area && show_emission) {
            const Color Le = area->eval_surface(si, -ray.d);
            if (!is_black(Le)) {
                const float w = prev_delta ? 1.f : emission_weight(*area, prev, direction_sample_from_hit(prev.p, si), prev_pdf);
                L += beta * Le * w;
            }
        }
        // A surface that scatters is one more vertex, past max_depth's last; one the path may pass
        // straight through is not.
        const bool last = bounded && depth + 1 >= options_.max_depth;
        if (last && !(si.shape->bsdf_flags & BSDFNull)) break;
        ScatteringPoint v;
        v.si = &si;
        v.p = si.p;
        v.wi = -ray.d;
        v.medium = medium;
        v.ctx = light_context(si, ray.d);
        if (!last && options_.nee && (si.shape->bsdf_flags & BSDFSmooth))
            L += sample_direct_volumetric(scene, v, beta, channel, sampler, counters);

        const BSDF &bsdf = *si.shape->bsdf;
        const float u1 = sampler.next_1d();
        const Vec2 u2 = sampler.next_2d();
        const BSDFSample bs = bsdf.sample(BSDFContext{}, si, si.wi, u1, u2);
        if (!bs.valid()) break;
        const bool passed = (bs.sampled_flags & BSDFNull) != 0;
        if (last && !passed) break;
        beta *= bs.weight;
        eta *= bs.eta;
        const Vec3 d = si.to_world(bs.wo);
        if (si.shape->is_medium_transition()) medium = si.shape->medium_toward(d, si.n);
        ray = si.spawn_ray(d);
        need_hit = true;
        if (passed) continue;
        ++depth;
        prev = v.ctx;
        prev_pdf = bs.pdf;
        prev_delta = (bs.sampled_flags & BSDFDelta) != 0;
        if (depth > options_.rr_depth && !survives_roulette(beta, eta, sampler)) break;
        if (!(max_component(beta) > 0)) break;
    }
    return L;
}

}  // namespace neepp
