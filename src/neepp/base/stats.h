// Per-thread render counters, summed after each pass. Kept plain (no atomics) because each worker owns one.
#pragma once
#include <cstdint>

namespace neepp {

struct RenderCounters {
    uint64_t rays = 0;               // closest-hit queries (camera and bounce rays)
    uint64_t shadow_rays = 0;        // occlusion queries actually traced
    uint64_t shadow_rays_occluded = 0;
    uint64_t shadow_rays_skipped = 0;  // shadow tests answered without tracing (NEE++ rejection)
    uint64_t occlusion_ticks = 0;    // time inside occlusion queries, in CPU timestamp ticks
    uint64_t invalid_samples = 0;    // NaN/inf radiance samples dropped
    // Light paths (light tracing, BDPT): their closest-hit queries (also counted in rays), and the
    // contributions splatted onto the film through camera connections.
    uint64_t light_rays = 0;
    uint64_t splats = 0;
    // Participating media: density lookups by the paths' free flights, and by the shadow rays'
    // transmittance estimates (ratio tracking: what a shadow ray that NEE++ skips saves), and the shadow
    // rays whose transmittance through a medium was estimated (not those an opaque surface stopped first).
    uint64_t density_lookups = 0;
    uint64_t transmittance_lookups = 0;
    uint64_t medium_shadow_rays = 0;

    RenderCounters &operator+=(const RenderCounters &o) {
        rays += o.rays; shadow_rays += o.shadow_rays; shadow_rays_occluded += o.shadow_rays_occluded;
        shadow_rays_skipped += o.shadow_rays_skipped; occlusion_ticks += o.occlusion_ticks;
        invalid_samples += o.invalid_samples; light_rays += o.light_rays; splats += o.splats;
        density_lookups += o.density_lookups; transmittance_lookups += o.transmittance_lookups;
        medium_shadow_rays += o.medium_shadow_rays;
        return *this;
    }
};

// CPU time in seconds of this process (all its threads) or of the calling thread alone: what the render
// loop reports as render_cpu_time_s and what neepp=auto's pilot charges each candidate.
enum class CpuClock { process, thread };
double cpu_seconds(CpuClock clock);

// Seconds per tick of the CPU timestamp counter, calibrated once against the steady clock.
double seconds_per_tick();
uint64_t read_ticks();

}  // namespace neepp
