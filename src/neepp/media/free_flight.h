// Distance sampling through a medium, one event at a time (delta tracking against the majorant), as the
// volumetric path tracer walks its paths and the visibility map's pre-pass finds where they scatter.
#pragma once
#include "neepp/base/medium.h"
#include "neepp/math/vec.h"

namespace neepp {

struct Ray;
class Sampler;

// What a free flight through a medium met before the surface ahead: the event, and its contribution f and
// density pdf in each channel, had that channel drawn the distance (the event's choice, real or null, is
// the same whichever did).
struct FreeFlight {
    enum Event { Passed, Real, Null } event = Passed;
    float t = 0;     // where the collision is, along the ray
    Color f{1.f};    // transmittance to it, times sigma_s (real) or sigma_n (null)
    Color pdf{1.f};  // the density of this distance (and event) in each channel
};

// A distance drawn in `channel` against the majorant from where the ray starts (tmin) up to t_end; at a
// collision, real with probability avg(sigma_t / majorant), else null. A collision looks the medium up
// once; Passed looks nothing up.
FreeFlight sample_free_flight(const Medium &medium, const Ray &ray, float t_end, int channel, Sampler &sampler);

// The flight that passed through to t_end without a collision: its weight and density, e^{-majorant d}
// per channel over the part of the ray the medium overlaps.
FreeFlight passed_free_flight(const Medium &medium, const Ray &ray, float t_end);

}  // namespace neepp
