#include "neepp/render/render_output.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <sys/resource.h>
#include "neepp/base/integrator.h"
#include "neepp/render/huge_pages.h"
#include "neepp/scene/scene.h"

namespace neepp {

// The peak resident set of this program image (VmHWM), not getrusage's ru_maxrss: Linux folds into
// ru_maxrss the peak of the address space that exec replaced, and a child that Python's subprocess
// starts (vfork, then exec) replaces its parent's, so ru_maxrss can report the benchmark script's own
// peak, far above the render's.
double peak_memory_mb() {
    if (std::ifstream status("/proc/self/status"); status) {
        std::string line;
        while (std::getline(status, line))
            if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // in kB
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in kilobytes on Linux
}

nlohmann::json render_statistics(const Scene &scene, const Integrator &integrator, const RenderResult &r,
                                 const RenderJob &job) {
    const RenderCounters &c = r.counters;
    double samples = double(r.spp) * scene.camera.width * scene.camera.height;
    nlohmann::json j = {
        {"scene", scene.source_path},
        {"integrator", integrator.describe()},
        {"spp", r.spp},
        {"passes", r.passes},
        {"stopped_by", r.stopped_by},
        {"resumed_spp", r.resumed_spp},
        {"width", scene.camera.width},
        {"height", scene.camera.height},
        {"seed", job.seed},
        {"threads", job.threads},
        {"sampler", job.sampler},
        {"render_time_s", r.render_time_s},
        {"render_cpu_time_s", r.render_cpu_time_s},
        {"samples_per_s", r.render_time_s > 0 ? samples / r.render_time_s : 0.0},
        {"rays", c.rays},
        {"camera_rays", c.rays - c.light_rays},
        {"light_rays", c.light_rays},
        {"splats", c.splats},
        {"shadow_rays", c.shadow_rays},
        {"shadow_rays_occluded", c.shadow_rays_occluded},
        {"shadow_rays_skipped", c.shadow_rays_skipped},
        {"occlusion_time_s", r.occlusion_time_s},
        {"invalid_samples", c.invalid_samples},
        {"density_lookups", c.density_lookups},
        {"transmittance_lookups", c.transmittance_lookups},
        {"medium_shadow_rays", c.medium_shadow_rays},
        {"triangles", scene.triangle_count()},
        {"lights", scene.lights().size()},
        {"peak_memory_mb", peak_memory_mb()},
        {"huge_pages", malloc_huge_pages()},
    };
    if (auto extra = integrator.statistics(); !extra.empty()) j["integrator_statistics"] = extra;
    return j;
}

std::string write_render_images(const std::string &exr_path, const Image &image) {
    write_exr(exr_path, image);
    std::filesystem::path png = exr_path;
    png.replace_extension(".png");
    write_png_srgb(png.string(), image);
    return png.string();
}

}  // namespace neepp
