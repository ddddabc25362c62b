// An integrator: ambient occlusion, the fraction of the hemisphere above the first hit that is open within
// a distance, weighted by the cosine. A RayIntegrator defines Li, one camera ray at a time; the render loop
// owns threads, passes, time, progress and checkpoints.
#include "neepp/base/stats.h"
#include "neepp/integrators/factory.h"
#include "neepp/math/warp.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"

namespace example {
using namespace neepp;

class AmbientOcclusion final : public RayIntegrator {
public:
    explicit AmbientOcclusion(float distance) : distance_(distance) {}

    Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters) const override {
        SurfaceInteraction si;
        ++counters.rays;
        if (!scene.intersect(ray, si)) return Color(0.f);
        // The side the camera sees: its geometric normal turned toward the ray's origin.
        const Vec3 n = dot(ray.d, si.n) > 0 ? -si.n : si.n;
        // A direction by the cosine about n: its estimate of ∫ cos V dω / π is V itself.
        const Vec3 d = Frame(n).to_world(square_to_cosine_hemisphere(sampler.next_2d()));
        Ray probe = si.spawn_ray(d);
        probe.tmax = distance_;
        ++counters.shadow_rays;
        return Color(scene.occluded(probe) ? 0.f : 1.f);
    }
    nlohmann::json describe() const override { return {{"name", "ao"}, {"distance", distance_}}; }

private:
    float distance_;
};

// neepp render SCENE.xml --integrator ao -I distance=0.5, or <integrator type="ao"> in the scene file.
void register_ambient_occlusion() {
    register_integrator("ao", [](const Options &options) -> std::unique_ptr<Integrator> {
        const float distance = options.get_float("distance", kInfinity);
        if (!(distance > 0.f)) throw std::invalid_argument("ao: distance must be positive");
        return std::make_unique<AmbientOcclusion>(distance);
    });
}

}  // namespace example
