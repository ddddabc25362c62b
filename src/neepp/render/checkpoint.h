// Render checkpoints: what a render has accumulated at the end of a pass, so that a render stopped at
// any moment (killed, out of time, Ctrl-C) can be continued by --resume to the same sums an
// uninterrupted render reaches. The image sums are kept as they are summed (doubles, splats in fixed
// point), never as the resolved image, so nothing is rounded on the way.
#pragma once
#include <cstdint>
#include <string>
#include <vector>
#include "neepp/base/stats.h"

namespace neepp {

struct RenderCheckpoint {
    // What the render is (scene, integrator and its options, seed, sampler, film), as the caller
    // describes it; resuming checks it against the render being resumed. JSON text.
    std::string identity;
    int spp = 0;                   // samples per pixel in the sums
    int passes = 0;
    double render_time_s = 0;      // rendering time so far, loading excluded
    double seconds_per_spp = 0;    // the last pass's speed, which sizes the next pass under a time limit
    double light_paths = 0;        // light paths behind the splats (their normalization)
    RenderCounters counters;
    std::vector<double> image_sums;   // ImageBlock::sums() of the whole image
    std::vector<int64_t> splat_sums;  // SplatFilm::sums(); empty for integrators that do not splat
    std::string integrator_state;     // Integrator::save_state()
    // A distributed render's driver (neepp.distributed): where its rounds stand and the statistics of the
    // ranges summed so far, as JSON it alone reads. Empty for a render of one machine.
    std::string driver;
};

// The checkpoint as its file holds it, with a checksum.
std::string checkpoint_bytes(const RenderCheckpoint &checkpoint);
// Writes the checkpoint atomically (see atomic_file.h).
void save_checkpoint(const std::string &path, const RenderCheckpoint &checkpoint);
// Reads one back; throws std::runtime_error naming the file when it is missing, damaged or not one.
RenderCheckpoint load_checkpoint(const std::string &path);

}  // namespace neepp
