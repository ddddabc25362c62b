// Writing what a render produced: the EXR, a tonemapped PNG beside it, and the statistics JSON.
#pragma once
#include <string>
#include <nlohmann/json.hpp>
#include "neepp/render/render_loop.h"

namespace neepp {

class Scene;
class Integrator;

// The statistics every render reports (integrator, spp, size, time, rays, shadow rays, memory...).
nlohmann::json render_statistics(const Scene &scene, const Integrator &integrator, const RenderResult &result,
                                 const RenderJob &job);
// Writes exr_path and the PNG next to it (same stem); returns the PNG path.
std::string write_render_images(const std::string &exr_path, const Image &image);
double peak_memory_mb();

}  // namespace neepp
