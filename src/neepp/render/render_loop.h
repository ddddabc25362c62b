// The render loop owns time: it renders the image in passes of whole-image samples, over tiles on a TBB
// thread pool, until the sample count or the time budget is reached or it is cancelled (Ctrl-C), and
// always hands back the image of the passes completed so far. Integrators get a hook between passes.
// It can save its state at pass boundaries and continue from such a checkpoint.
#pragma once
#include <atomic>
#include <functional>
#include <string>
#include "neepp/base/stats.h"
#include "neepp/io/image.h"
#include "neepp/render/checkpoint.h"
#include "neepp/render/progress_bar.h"

namespace neepp {

class Scene;
class Integrator;

// What a live view of the render is shown (RenderJob::on_display): the image so far and what made it.
// Within a pass (RenderJob::display_within_pass) the pixels of the tiles the pass has finished have its
// samples too, the others not yet: spp is what every pixel has, spp_max what the most have, spp_mean the
// mean over the pixels; between passes the three are equal. Within the first pass (RenderJob::
// display_first_pass) spp is 0, and the pixels of the tiles not finished yet, which have no sample at all,
// are NaN.
struct DisplayFrame {
    Image image;
    int spp = 0;                // samples per pixel that every pixel of the image has
    double render_time_s = 0;
    RenderCounters counters;    // of the samples in the image (within a pass: of the completed passes)
    bool final = false;         // the render's last image
    int spp_max = 0;
    double spp_mean = 0;
    // Shown while a pass runs (from a thread of the render loop's own, not a tile worker): what the
    // integrator learns between passes is changing, so the callback must not read it then.
    bool within_pass = false;
};

struct RenderJob {
    int spp = 16;                 // target samples per pixel; 0 = as many as time_limit_s allows
    double time_limit_s = 0;      // 0 = no limit
    uint64_t seed = 0;
    int threads = 0;              // 0 = all cores
    std::string sampler = "independent";
    ProgressStyle progress = ProgressStyle::none;  // a bar with ETA on stderr, or log lines
    // Called a few times a second, from a thread of the render's own, with the fraction done and the
    // seconds elapsed (the Python package's progress callback).
    std::function<void(double fraction, double elapsed_s)> on_progress;
    const std::atomic<bool> *cancel = nullptr;  // set asynchronously (e.g. by SIGINT) to stop early
    int tile_size = 32;
    // Checkpoints: at the end of a pass, once checkpoint_interval_s has passed since the last, and when
    // the render stops before its sample count (time, cancel), on_checkpoint gets the render's state and
    // its image so far. `resume` continues the render a checkpoint holds (same scene, integrator, seed
    // and sampler: the caller checks its identity) to the sums an uninterrupted render reaches.
    double checkpoint_interval_s = 0;
    std::function<void(const RenderCheckpoint &, const Image &)> on_checkpoint;
    const RenderCheckpoint *resume = nullptr;
    // Snapshots of the image as it converges (convergence plots): after the first pass, then after each
    // pass that ends once the render time has grown snapshot_growth times since the last snapshot.
    double snapshot_growth = 1.5;
    std::function<void(int spp, double render_time_s, const Image &)> on_snapshot;
    // A live view of the image as it converges (a viewer such as tev, neepp render --display-server, or
    // neepp view): after a pass that ends once display_interval_s has passed since the last (longer for an
    // image so large that resolving it would cost more than about 5 % of the render), on_display gets the
    // image so far with its sample count and counters, and at the end the final image. It runs on the
    // render's thread between passes, so it must return at once (TevDisplay hands the image to a thread of
    // its own); it only reads, so the image is the same with it or without.
    double display_interval_s = 0.25;
    std::function<void(DisplayFrame)> on_display;
    // Also show the image while a pass runs, display_interval_s apart, once a first pass is complete: the
    // completed passes with the tiles of the running pass that are finished (DisplayFrame::within_pass),
    // so that a pass longer than the interval (a slow scene, a large image) does not hold the image back.
    // on_display is then called from a second thread of the render's own too (never at once with the
    // first), and each tile's samples are kept until the pass ends (about 32 more bytes per pixel).
    bool display_within_pass = false;
    // With display_within_pass, show the first pass under way too: its finished tiles, and NaN in the pixels
    // of the others (no sample has reached them). For a caller that has something of its own to show there
    // (neepp view fills them from its coarse image of the view); a plain viewer would show holes. Not for a
    // splatting integrator: the first pass's splats are normalised by its light paths, counted at its end.
    bool display_first_pass = false;
    // 0: passes as large as the render loop likes (up to 32 spp). An interactive view (neepp view) sets
    // about its display interval: each pass then takes about that long at the last pass's speed (at least
    // one sample per pixel), so that the image can be shown that often.
    double max_pass_s = 0;
    // The integrator was prepared by an earlier render of this scene and continues from what it has
    // learned since, instead of being prepared afresh (neepp view: a camera move restarts the image, not
    // NEE++'s visibility map, which belongs to the scene and keeps learning). The caller keeps the scene
    // as the integrator was prepared for, but for the camera.
    bool prepared = false;
    // Distributed rendering splits an image by sample index: this render's samples are first_sample ..
    // spp - 1 (the image holds spp - first_sample of them), what the integrator learns starts from
    // integrator_state (what renders of earlier ranges learned, restored right after prepare) when given,
    // and the result carries its sums (RenderResult::state), which add up across ranges.
    int first_sample = 0;
    const std::string *integrator_state = nullptr;
    bool keep_state = false;
};

struct RenderResult {
    Image image;
    int spp = 0;                   // samples per pixel actually in the image
    int passes = 0;
    double render_time_s = 0;
    // CPU time of all the process's threads over the same span (this run's only, when resumed): with one
    // thread, a measure of the work that other processes on a shared machine do not inflate.
    double render_cpu_time_s = 0;
    RenderCounters counters;
    double occlusion_time_s = 0;
    std::string stopped_by = "spp";  // spp, time, cancel
    int resumed_spp = 0;             // samples per pixel the render was resumed with (0: not resumed)
    RenderCheckpoint state;          // with RenderJob::keep_state: the sums and the integrator's state at the end
};

RenderResult render(const Scene &scene, Integrator &integrator, const RenderJob &job);

// The image that a render's sums make (RenderCheckpoint's image_sums, splat_sums and light_paths; those of
// several renders of different sample ranges added up), with the scene's film and filter.
Image image_from_sums(const Scene &scene, const std::vector<double> &image_sums, const std::vector<int64_t> &splat_sums,
                      double light_paths, double splat_scale = 1.0);

}  // namespace neepp
