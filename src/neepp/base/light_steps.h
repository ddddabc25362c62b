// A speed hook of lights (Light::steps): a light sample taken in steps, for batched integrators, which
// take each step for many paths before the next, so that the memory one step reads is fetched while
// the other paths take theirs (an environment map's sample is otherwise a chain of cache misses):
//   prefetch(u)            a cache prefetch of what u alone locates (a hint: never changes a result);
//   begin(u)               the work u alone determines, and a prefetch of what finishing reads;
//   finish(ref, start)     the rest: finish(ref, begin(u)) is the light's sample_direction(ref, u).
#pragma once
#include "neepp/base/light.h"

namespace neepp {

// A light sample begun, for finish: its variates, and what the light computed from them alone (an
// environment map: the map point and its density in uv).
struct LightSampleStart {
    Vec2 u;
    Vec2 point{0.f, 0.f};
    float density = 0;
};

class LightSampleSteps {
public:
    virtual ~LightSampleSteps() = default;
    virtual void prefetch(Vec2 u) const {}
    virtual LightSampleStart begin(Vec2 u) const = 0;
    virtual DirectionSample finish(const Vec3 &ref, const LightSampleStart &start, Color &radiance) const = 0;
};

}  // namespace neepp
