// Shadow rays through participating media and surfaces that let light through (null, thin dielectric,
// mask): what the volumetric path tracer's next event estimation asks instead of "is it occluded?". The
// answer is a transmittance in [0, 1] per channel, and NEE++'s visibility map learns, per voxel pair, the
// expected transmittance in place of the fraction of rays that got through.
#pragma once
#include "neepp/base/medium.h"
#include "neepp/base/shadow_ray_tester.h"

namespace neepp {

class Scene;
class Sampler;

// The transmittance along ray (from its origin to its tmax), starting in `medium` (null: vacuum): the
// product over the surfaces it crosses of what each lets through (BSDF::null_transmission), the medium
// switching where a surface bounds one, and over the medium segments between them of their transmittance
// (a homogeneous medium's exactly; others by ratio tracking in `channel` against the majorant). Counts
// one shadow ray, its surface queries and its time.
Color trace_transmittance(const Scene &scene, const Ray &ray, const Medium *medium, int channel, Sampler &sampler,
                          RenderCounters &counters);

// One query tested as test_visibility tests it, the traced ray's answer a transmittance T: the weight of
// the unoccluded contribution is if_occluded + T (if_visible - if_occluded) when traced, if_skipped when
// not. Every policy's weight is affine in the outcome, so its expectation is E[T] whatever the policy
// decided with: unbiased as for binary visibility. The tester learns "visible" with probability avg(T).
Color test_transmittance(const ShadowRayTester &tester, const Scene &scene, const ShadowQuery &q, const Medium *medium,
                         int channel, Sampler &sampler, RenderCounters &counters);

}  // namespace neepp
