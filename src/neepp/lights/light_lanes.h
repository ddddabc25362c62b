// Light samples taken eight at a time, one AVX lane each: next event estimation's point, direction,
// distance and density toward a parallelogram light of constant radiance (Mitsuba's `rectangle` emitter,
// the only light of bathroom, cornell-box, staircase and veach-ajar), for a batch's paths together.
//
// Why: one such sample is a few dozen operations, but a square root, then a division that needs it, then
// another that needs both, each waiting on the last (long latency); scalar, it takes more time than its
// count of instructions suggests. In lanes, eight share each wait.
#pragma once
#include <cstddef>

#include "neepp/base/light.h"

namespace neepp {

// What the kernel reads of a light: 16 floats, two rows of 8 for its transposes. The parallelogram
// p0 + u.x e1 + u.y e2 with unit normal n (its shading normal too), its area density (1 / area) and radiance.
struct alignas(32) LightLaneRecord {
    Vec3 p0, e1, e2, n;
    float pdf = 0;
    Color radiance;
};
static_assert(sizeof(LightLaneRecord) == 64);

// A light sample and the radiance it carries, as AreaLight::sample_direction returns them.
struct LightSample {
    DirectionSample ds;
    Color radiance;
};

class LightSampleLanes {
public:
    static constexpr int kLanes = 8;
    // Without AVX there is no kernel: lights have no lane record, and are sampled by sample_direction.
#if defined(__AVX__)
    static constexpr bool kEnabled = true;
#else
    static constexpr bool kEnabled = false;
#endif

    // Queues a sample of light from ref with u, written to out when the lanes are filled: on the eighth,
    // or at flush().
    void add(const LightLaneRecord &light, const Vec3 &ref, Vec2 u, LightSample &out) {
        const int i = n_;
        rx_[i] = ref.x, ry_[i] = ref.y, rz_[i] = ref.z, ux_[i] = u.x, uy_[i] = u.y;
        light_[i] = &light;
        out_[i] = &out;
        if (++n_ == kLanes) flush();
    }
    // Fills the queued samples: the same distribution as AreaLight::sample_direction, its invalid samples
    // (the light's back, a reference point on the light) with zero density and radiance. A lane's result
    // depends only on its own inputs; it may differ from the scalar one in the last bits (the order of
    // fused operations).
    void flush();

private:
    alignas(32) float rx_[kLanes], ry_[kLanes], rz_[kLanes], ux_[kLanes], uy_[kLanes];
    const LightLaneRecord *light_[kLanes];
    LightSample *out_[kLanes];
    int n_ = 0;
};

}  // namespace neepp
