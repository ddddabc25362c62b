#include "neepp/render/render_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include "neepp/base/integrator.h"
#include "neepp/base/stats.h"
#include "neepp/math/denormals.h"
#include "neepp/render/film.h"
#include "neepp/render/memory.h"
#include "neepp/render/progress_bar.h"
#include "neepp/render/render_budget.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"

namespace neepp {
namespace {

// Camera samples handed to a ray integrator at once (RayIntegrator::batch).
constexpr int kBatch = 32;

struct Tile {
    int x0, y0, w, h;
};

std::vector<Tile> make_tiles(int width, int height, int size) {
    std::vector<Tile> tiles;
    for (int y = 0; y < height; y += size)
        for (int x = 0; x < width; x += size) tiles.push_back({x, y, std::min(size, width - x), std::min(size, height - y)});
    return tiles;
}

// Per-sample variance of the pixel estimates, from this pass's second moment and the image so far (see
// PassStatistics). Floored at 1% of the second moment so a noise-free image does not give zero.
PassStatistics pass_statistics(int pass_index, int spp, int pass_size, const std::vector<double> &tile_m2,
                               const ImageBlock &accumulated) {
    PassStatistics ps;
    ps.pass_index = pass_index;
    ps.spp = spp;
    const Image img = accumulated.resolve();
    const double pixels = double(img.width) * img.height;
    double m2 = 0, mean_sq = 0;
    for (double v : tile_m2) m2 += v;
    m2 /= pixels * pass_size;
    for (size_t i = 0; i < size_t(img.width) * img.height; ++i) {
        double l = luminance(Color(img.data[3 * i], img.data[3 * i + 1], img.data[3 * i + 2]));
        mean_sq += l * l;
    }
    mean_sq /= pixels;
    ps.sample_variance = std::max(m2 - mean_sq, 0.01 * m2);
    return ps;
}


// A frame within the first pass: NaN in every pixel outside the finished tiles, which has no sample of its
// own yet (one beside a finished tile has that tile's share through the filter's border, but from one side
// only: not an estimate of the pixel).
void mark_unsampled(Image &image, const std::vector<Tile> &tiles, const std::vector<size_t> &finished) {
    std::vector<uint8_t> sampled(size_t(image.width) * image.height, 0);
    for (size_t i : finished) {
        const Tile &t = tiles[i];
        for (int y = t.y0; y < t.y0 + t.h; ++y)
            std::fill_n(sampled.begin() + ptrdiff_t(size_t(y) * image.width + t.x0), t.w, uint8_t(1));
    }
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (size_t i = 0; i < sampled.size(); ++i)
        if (!sampled[i]) std::fill_n(image.data.begin() + ptrdiff_t(3 * i), 3, nan);
}

// The image: the accumulated samples plus the splat layer (if any), scaled by pixels / light paths.
Image combine_layers(const ImageBlock &samples, const SplatFilm *splats, double light_paths, double splat_scale) {
    Image image = samples.resolve();
    if (splats && light_paths > 0) {
        const Image splat = splats->resolve(double(image.width) * image.height / light_paths * splat_scale);
        for (size_t i = 0; i < image.data.size(); ++i) image.data[i] += splat.data[i];
    }
    return image;
}

// TBB's worker threads are one pool for the whole process, and a tbb::global_control sizes that pool for
// the whole process, the smallest of all those alive winning. A render that held one at its own thread
// count (as this loop once did) cut every render running beside it (another Python thread's, a view's)
// down to that count, and a render with threads=1 stopped the others' workers altogether. So a render's
// thread count is the size of its task_arena alone, everything the render does running in that arena
// (render()), and the pool is only ever raised: to the largest count that a running render asks for
// beyond the cores (--threads 32 on 16 cores), so that such an arena can fill; back to TBB's default when
// the last of them ends.
class WorkerPoolLease {
public:
    explicit WorkerPoolLease(size_t threads) : threads_(threads) {
        Pool &p = pool();
        std::lock_guard<std::mutex> lock(p.mutex);
        p.asked.insert(threads_);
        p.resize();
    }
    ~WorkerPoolLease() {
        Pool &p = pool();
        std::lock_guard<std::mutex> lock(p.mutex);
        p.asked.erase(p.asked.find(threads_));
        p.resize();
    }
    WorkerPoolLease(const WorkerPoolLease &) = delete;
    WorkerPoolLease &operator=(const WorkerPoolLease &) = delete;

private:
    struct Pool {
        std::mutex mutex;
        std::multiset<size_t> asked;  // the thread counts of the renders running
        size_t raised_to = 0;         // 0: not raised (TBB's default, the cores)
        std::unique_ptr<tbb::global_control> control;
        void resize() {
            const size_t cores = size_t(tbb::info::default_concurrency());
            const size_t want = asked.empty() || *asked.rbegin() <= cores ? 0 : *asked.rbegin();
            if (want == raised_to) return;
            // The new limit exists before the old goes: the pool never drops to the default in between.
            std::unique_ptr<tbb::global_control> next;
            if (want > 0) next = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, want);
            control = std::move(next);
            raised_to = want;
        }
    };
    static Pool &pool() {
        static Pool p;
        return p;
    }
    const size_t threads_;
};

// One call of render(): the image so far, its passes, and what the render loop reports and saves.
class RenderLoop {
public:
    // Before any memory is taken: a job that says how long to render, and a film that fits.
    static void check_job(const Scene &scene, const Integrator &integrator, const RenderJob &job) {
        if (job.spp <= 0 && !(job.time_limit_s > 0)) throw std::invalid_argument("render: give a sample count or a time limit");
        // Per pixel: the image and the pass (ImageBlock, 32 bytes each), the image resolved for the pass
        // statistics and for the result (12 each), the PNG's bytes (4); with splats, two splat films (24
        // bytes each) and the splat layer resolved (12).
        // Frames within a pass keep each tile's block (with its border) and copy the image (32 each).
        check_film_fits_in_memory(scene.camera.width, scene.camera.height,
                                  2 * 32 + 2 * 12 + 4 + (splats(integrator) ? 2 * 24 + 12 : 0) +
                                      (job.display_within_pass && job.on_display ? 2 * 32 + 12 : 0));
    }

    RenderLoop(const Scene &scene, Integrator &integrator, const RenderJob &job);
    // The whole render in its own arena: the integrator's preparation and between-pass work (NEE++'s
    // map seeding, its merges) with their parallel loops included, which would otherwise run in the
    // calling thread's default arena on every core, not the threads the job asks for.
    RenderResult run() {
        return arena_.execute([this] { return run_in_arena(); });
    }
    ~RenderLoop() { stop_display_thread(); }

private:
    RenderResult run_in_arena();
    // The image between passes, when the display interval has passed (the render's thread).
    void show_between_passes();
    // Frames within a pass (RenderJob::display_within_pass): the display thread's loop, the frame it
    // makes of the completed passes and the tiles of the running pass published so far (none when there
    // is nothing new since the frame of that pass shown last), and its end.
    void display_within_passes();
    std::optional<DisplayFrame> frame_within_pass(int &pass, size_t &tiles_shown);
    void stop_display_thread();

    bool cancelled() const { return job_.cancel && job_.cancel->load(); }
    // One pass of `size` samples per pixel into pass_block_ (and splats_pass_); false when it was cut short.
    bool render_pass(int size);
    // What a thread of the tile loop reuses from tile to tile: a batch's samplers, rays, film positions
    // and radiances.
    struct Batch {
        std::vector<std::unique_ptr<Sampler>> owned;
        std::vector<Sampler *> samplers;
        std::vector<Ray> rays;
        std::vector<Vec2> film_pos;
        std::vector<Color> radiance;
    };
    // The tile loop's share of a pass: each tile's samples, in batches, into the tile's block.
    void render_tile(size_t index, int s0, int size, Batch &batch, RenderCounters &c);
    // A finished tile's block into pass_block_, in tile order (see waiting_).
    void merge_tile(size_t index, std::unique_ptr<ImageBlock> own);
    void merge_tiles_left();
    void merge_in_order(bool past_unfinished);  // under merge_mutex_
    void merge_pass(uint64_t pass_light_paths);
    // Light paths the pass's camera samples splatted (an integrator's own pass body counts its own).
    double camera_sample_light_paths() const {
        return splatter_ ? splatter_->light_paths_per_sample() * double(samples_done_) : 0.0;
    }
    Image current_image() const {
        return combine_layers(accumulated_, splats_accumulated_.get(), light_paths_, passes_ ? passes_->splat_scale() : 1.0);
    }
    RenderCounters counted() const {
        RenderCounters sum = counters_before_;
        for (const RenderCounters &t : counters_) sum += t;
        return sum;
    }
    RenderCheckpoint make_checkpoint(const RenderCounters &counted_so_far) const;
    void checkpoint(const RenderCounters &counted_so_far) {
        job_.on_checkpoint(make_checkpoint(counted_so_far), current_image());
        last_checkpoint_ = budget_.elapsed();
    }

    const Scene &scene_;
    Integrator &integrator_;
    const RenderJob &job_;
    const Camera &cam_;
    const int W_, H_;
    // The integrator's family (integrators/integrator.h): one of the three is set.
    RayIntegrator *const ray_;
    SplattingIntegrator *const splatter_;
    PassIntegrator *const passes_;
    const bool splatting_;  // the image has a splat layer (a splatting or a pass integrator)
    ReconstructionFilter filter_;
    int border_ = 0;  // how far a sample's filter reaches beyond its pixel
    // The image (samples, and the splat layer of integrators whose samples add to other pixels, scaled by
    // pixels / light paths), and the pass being rendered.
    ImageBlock accumulated_, pass_block_;
    std::unique_ptr<SplatFilm> splats_accumulated_, splats_pass_;
    double light_paths_ = 0;
    std::mutex merge_mutex_;
    std::vector<Tile> tiles_;
    // Tiles are added to pass_block_ in tile order, whichever finishes first: a pixel near a tile's edge
    // takes samples from up to four tiles' blocks, and sums in the order the tiles finish would differ in
    // their last bits from one multithreaded render to the next. A tile finished before its turn waits
    // here (its block, or only its mark where tile_blocks_ keeps it); the tile loop hands tiles out
    // roughly in order, so few wait. Under merge_mutex_.
    std::vector<std::unique_ptr<ImageBlock>> waiting_;
    std::vector<char> finished_;
    size_t next_merge_ = 0;
    std::vector<double> tile_m2_;  // Σ lum(L)² per tile this pass, summed in tile order
    const std::unique_ptr<Sampler> prototype_;
    const int threads_;
    const WorkerPoolLease pool_;
    tbb::task_arena arena_;
    tbb::enumerable_thread_specific<RenderCounters> counters_;
    RenderCounters counters_before_;        // a resumed render's
    RenderCounters counted_at_pass_start_;  // what a checkpoint of a pass cut short holds
    RenderBudget budget_;
    const double cpu_start_;
    std::atomic<uint64_t> samples_done_{0};  // camera samples completed this pass
    std::atomic<int> spp_done_now_{0};
    std::atomic<bool> aborted_{false};
    double one_off_s_ = 0;  // seconds of the pass spent on one-off work (PSSMLT's bootstrap)
    double seconds_per_spp_ = 0;
    double last_checkpoint_ = 0, last_snapshot_ = 0;
    // When the last frame shown began: frames are display_wait_ apart from start to start, so that what a
    // frame takes (its image resolved, on_display, on a loaded machine the wait for a core) does not add to
    // the interval.
    double last_display_ = -std::numeric_limits<double>::infinity();  // the first pass is shown
    double display_wait_ = 0;
    RenderResult result_;

    // Frames within a pass. A tile's worker fills the tile's own block, hands it to pass_block_ as
    // always (so the image and its sums are the same with these frames or without), and then publishes
    // the block (release); the display thread reads only published blocks (acquire), which no one writes
    // again until the next pass, whose start clears the marks under pass_state_mutex_. The workers take no
    // lock of the display's and never wait for it; the render's thread takes pass_state_mutex_ at a pass's
    // start and end only (the display thread holds it while it copies the image, a few milliseconds).
    const bool display_within_pass_;
    const bool display_first_pass_;  // RenderJob::display_first_pass, where it applies
    std::vector<std::unique_ptr<ImageBlock>> tile_blocks_;
    std::unique_ptr<std::atomic<bool>[]> tile_published_;
    std::atomic<size_t> tiles_published_{0};
    // accumulated_, the splats and light_paths_ (written by the render's thread, under it, at a pass's
    // end only) and the running pass, as the display thread reads them.
    std::mutex pass_state_mutex_;
    struct PassState {
        bool running = false;
        int passes = 0;      // completed before it
        int spp = 0;         // samples per pixel of the completed passes
        int size = 0;        // its samples per pixel
        RenderCounters counted;  // of the completed passes
    } pass_state_;
    // One on_display call at a time, from either thread; last_display_, display_wait_, what was shown
    // last, the display thread's stop and an exception its on_display threw (raised by the render).
    std::mutex display_mutex_;
    std::condition_variable display_wake_;
    bool display_stop_ = false;
    int shown_passes_ = 0;  // completed passes in the newest frame shown
    int shown_within_ = -1;  // the index of the last pass shown under way
    std::exception_ptr display_error_;
    std::thread display_thread_;
};

RenderLoop::RenderLoop(const Scene &scene, Integrator &integrator, const RenderJob &job)
    : scene_(scene), integrator_(integrator), job_(job), cam_(scene.camera), W_(cam_.width), H_(cam_.height),
      ray_(dynamic_cast<RayIntegrator *>(&integrator)), splatter_(dynamic_cast<SplattingIntegrator *>(&integrator)),
      passes_(dynamic_cast<PassIntegrator *>(&integrator)), splatting_(splats(integrator)),
      filter_(scene.settings.rfilter, scene.settings.rfilter_radius, scene.settings.rfilter_stddev),
      accumulated_((check_job(scene, integrator, job), 0), 0, W_, H_, &filter_), pass_block_(0, 0, W_, H_, &filter_),
      tiles_(make_tiles(W_, H_, job.tile_size)), waiting_(tiles_.size()), finished_(tiles_.size()),
      tile_m2_(tiles_.size()),
      prototype_(make_sampler(job.sampler, job.seed)),
      threads_(job.threads > 0 ? job.threads : tbb::info::default_concurrency()),
      pool_(size_t(threads_)), arena_(threads_), budget_(job),
      cpu_start_(cpu_seconds(CpuClock::process)),
      // PSSMLT's pass body has no tiles: its image is all of its chains' splats, known only at the pass's end.
      display_within_pass_(job.display_within_pass && bool(job.on_display) && !passes_),
      display_first_pass_(display_within_pass_ && job.display_first_pass && !splatting_) {
    border_ = int(std::ceil(filter_.radius() - 0.5f));
    if (splatting_) {
        splats_accumulated_ = std::make_unique<SplatFilm>(W_, H_, &filter_);
        splats_pass_ = std::make_unique<SplatFilm>(W_, H_, &filter_);
    }
    if (display_within_pass_) {
        for (const Tile &t : tiles_)
            tile_blocks_.push_back(std::make_unique<ImageBlock>(t.x0 - border_, t.y0 - border_, t.w + 2 * border_,
                                                                t.h + 2 * border_, &filter_));
        tile_published_.reset(new std::atomic<bool>[tiles_.size()]);
        for (size_t i = 0; i < tiles_.size(); ++i) tile_published_[i].store(false, std::memory_order_relaxed);
    }
}

RenderResult RenderLoop::run_in_arena() {
    ProgressBar bar([this] { return budget_.fraction(spp_done_now_.load() + double(samples_done_.load()) / (double(W_) * H_)); },
                    job_.progress, job_.on_progress);
    if (!job_.prepared) integrator_.prepare(scene_);
    if (job_.resume) {  // continue the render a checkpoint holds
        const RenderCheckpoint &c = *job_.resume;
        if (splatting_ != !c.splat_sums.empty()) throw std::invalid_argument("resume: the checkpoint's splats do not match the integrator");
        accumulated_.set_sums(c.image_sums);
        if (splatting_) splats_accumulated_->set_sums(c.splat_sums);
        light_paths_ = c.light_paths;
        result_.spp = result_.resumed_spp = c.spp;
        result_.passes = c.passes;
        seconds_per_spp_ = c.seconds_per_spp;
        counters_before_ = c.counters;
        spp_done_now_ = result_.spp;
        integrator_.restore_state(scene_, c.integrator_state);
    }
    if (!job_.resume && job_.first_sample > 0) {  // a range of sample indices (distributed rendering)
        if (job_.spp <= job_.first_sample) throw std::invalid_argument("render: the sample range is empty");
        result_.spp = job_.first_sample;
        spp_done_now_ = result_.spp;
    }
    if (!job_.resume && job_.integrator_state) integrator_.restore_state(scene_, *job_.integrator_state);

    last_checkpoint_ = budget_.elapsed();
    bool checkpointed_at_stop = false;
    if (display_within_pass_) display_thread_ = std::thread([this] { display_within_passes(); });
    for (;;) {
        if (cancelled()) { result_.stopped_by = "cancel"; break; }
        if (budget_.timed() && budget_.remaining() <= 0) { result_.stopped_by = "time"; break; }
        const int size = budget_.next_pass_size(result_.spp, seconds_per_spp_, integrator_.learns_between_passes());
        if (size <= 0) { result_.stopped_by = budget_.spp_reached(result_.spp) ? "spp" : "time"; break; }

        const double pass_start = budget_.elapsed();
        if (!render_pass(size)) {
            // A checkpoint holds whole passes: the one cut short is not in it (nor in a resumed image).
            if (job_.on_checkpoint && result_.passes > 0) checkpoint(counted_at_pass_start_);
            checkpointed_at_stop = true;
            result_.stopped_by = cancelled() ? "cancel" : "time";
            break;
        }
        result_.spp += size;
        spp_done_now_ = result_.spp;
        integrator_.end_pass(scene_, pass_statistics(result_.passes, result_.spp, size, tile_m2_, accumulated_));
        ++result_.passes;
        seconds_per_spp_ = std::max(budget_.elapsed() - pass_start - one_off_s_, 0.0) / size;
        if (job_.on_snapshot && (last_snapshot_ == 0 || budget_.elapsed() >= job_.snapshot_growth * last_snapshot_)) {
            last_snapshot_ = budget_.elapsed();
            job_.on_snapshot(result_.spp, last_snapshot_, current_image());
        }
        if (budget_.spp_reached(result_.spp)) { result_.stopped_by = "spp"; break; }  // the final image is shown below
        if (job_.on_display) show_between_passes();
        if (job_.on_checkpoint && budget_.elapsed() - last_checkpoint_ >= job_.checkpoint_interval_s) checkpoint(counted());
    }
    // Stopped before its sample count between passes (time, Ctrl-C): what a resume continues from.
    if (job_.on_checkpoint && result_.stopped_by != "spp" && !checkpointed_at_stop && result_.passes > 0) checkpoint(counted());
    stop_display_thread();  // no frame of a pass after the final one
    if (display_error_) std::rethrow_exception(display_error_);
    bar.finish();

    result_.render_time_s = budget_.elapsed();
    result_.render_cpu_time_s = cpu_seconds(CpuClock::process) - cpu_start_;
    result_.counters = counted();
    result_.occlusion_time_s = double(result_.counters.occlusion_ticks) * seconds_per_tick();
    result_.image = current_image();
    if (job_.on_display)
        job_.on_display(DisplayFrame{result_.image, result_.spp, result_.render_time_s, result_.counters, true,
                                     result_.spp, double(result_.spp), false});
    if (job_.keep_state) result_.state = make_checkpoint(result_.counters);
    return std::move(result_);
}

bool RenderLoop::render_pass(int size) {
    const int s0 = result_.spp;
    if (job_.on_checkpoint) counted_at_pass_start_ = counted();
    pass_block_.clear();
    std::fill(finished_.begin(), finished_.end(), 0);
    next_merge_ = 0;
    {
        const std::lock_guard<std::mutex> lock(pass_state_mutex_);
        if (display_within_pass_) {
            for (size_t i = 0; i < tiles_.size(); ++i) tile_published_[i].store(false, std::memory_order_relaxed);
            tiles_published_.store(0, std::memory_order_relaxed);
        }
        pass_state_ = PassState{true, result_.passes, s0, size, display_within_pass_ ? counted() : RenderCounters{}};
    }
    samples_done_ = 0;
    aborted_ = false;
    one_off_s_ = 0;
    // Cancellation (Ctrl-C, SIGTERM) and a bad overrun of the time limit end the pass where it is.
    auto must_stop = [this] {
        if (cancelled() || budget_.overrun(result_.passes)) aborted_ = true;
        return aborted_.load(std::memory_order_relaxed);
    };
    // Light paths splatted apart from the camera samples (BDPT's NEE++ pool before the pass) or the
    // samples of an integrator's own pass body.
    uint64_t pass_light_paths = 0;
    const PassInfo info{result_.passes, s0, size, uint64_t(W_) * H_ * size, job_.seed};
    if (splatting_) {
        splats_pass_->clear();
        if (splatter_)
            arena_.execute([&] { pass_light_paths = splatter_->begin_pass(scene_, info, *splats_pass_, counters_.local()); });
    }
    if (passes_) {
        const PassControl control{must_stop, &samples_done_, &one_off_s_};
        arena_.execute([&] { pass_light_paths = passes_->render_pass(scene_, info, *splats_pass_, counters_.local(), control); });
    } else arena_.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles_.size(), 1), [&](const tbb::blocked_range<size_t> &r) {
            const DenormalsAreZero ftz;
            // Samples go to the integrator in batches (its fast form, RayIntegrator::batch), each with its own sampler.
            Batch batch{{}, {}, std::vector<Ray>(kBatch), std::vector<Vec2>(kBatch), std::vector<Color>(kBatch)};
            for (int k = 0; k < kBatch; ++k) batch.samplers.push_back(batch.owned.emplace_back(prototype_->clone()).get());
            RenderCounters &c = counters_.local();
            for (size_t ti = r.begin(); ti != r.end(); ++ti) {
                if (aborted_.load(std::memory_order_relaxed) || must_stop()) return;
                render_tile(ti, s0, size, batch, c);
            }
        });
    });
    merge_tiles_left();
    const std::lock_guard<std::mutex> lock(pass_state_mutex_);
    pass_state_.running = false;
    // Keep a partial first pass rather than nothing at all: every pixel it reached is unbiased.
    if (!aborted_ || result_.passes == 0) merge_pass(pass_light_paths);
    return !aborted_;
}

void RenderLoop::render_tile(size_t index, int s0, int size, Batch &batch, RenderCounters &c) {
    const Tile &t = tiles_[index];
    std::vector<Sampler *> &samplers = batch.samplers;
    std::vector<Ray> &rays = batch.rays;
    std::vector<Vec2> &film_pos = batch.film_pos;
    std::vector<Color> &radiance = batch.radiance;
    double m2 = 0;
    // The tile's samples: a block of its own, kept for the display thread when it shows passes under way.
    std::unique_ptr<ImageBlock> own;
    ImageBlock &block = display_within_pass_
                            ? (tile_blocks_[index]->clear(), *tile_blocks_[index])
                            : *(own = std::make_unique<ImageBlock>(t.x0 - border_, t.y0 - border_, t.w + 2 * border_,
                                                                   t.h + 2 * border_, &filter_));
    int queued = 0;
    auto add = [&](const Vec2 &pos, Color L) {
        // Only NaN/inf are dropped: negative values are legitimate for unbiased estimators such as NEE++'s
        // control variate and must average out.
        if (!is_finite(L)) {
            ++c.invalid_samples;
            L = Color(0.f);
        }
        block.put(pos.x, pos.y, L);
        m2 += double(luminance(L)) * double(luminance(L));
    };
    auto flush = [&] {
        Li_batch(*ray_, scene_, std::span<const Ray>(rays.data(), queued),
                             std::span<Sampler *const>(samplers.data(), queued), std::span<Color>(radiance.data(), queued), c);
        for (int k = 0; k < queued; ++k) add(film_pos[k], radiance[k]);
        queued = 0;
    };
    for (int y = t.y0; y < t.y0 + t.h; ++y)
        for (int x = t.x0; x < t.x0 + t.w; ++x)
            for (int s = s0; s < s0 + size; ++s) {
                Sampler &sampler = *samplers[queued];
                // Film pixels, so that a crop's pixels draw what the whole film's do.
                sampler.start_sample(uint32_t(x + cam_.crop_x), uint32_t(y + cam_.crop_y), uint32_t(s));
                Vec2 jitter = sampler.next_2d();
                film_pos[queued] = Vec2(float(x) + jitter.x, float(y) + jitter.y);
                // As Mitsuba: a lens's sample follows the film position's.
                const Vec2 lens = cam_.has_lens() ? sampler.next_2d() : Vec2(0.5f, 0.5f);
                rays[queued] = cam_.pixel_ray(x, y, jitter, lens);
                if (splatter_) {
                    add(film_pos[queued], splatter_->Li(scene_, rays[queued], sampler, c, *splats_pass_));
                    continue;
                }
                if (++queued == kBatch) flush();
            }
    if (queued > 0) flush();
    tile_m2_[index] = m2;
    samples_done_ += uint64_t(t.w) * t.h * size;
    merge_tile(index, std::move(own));
    if (display_within_pass_) {
        tile_published_[index].store(true, std::memory_order_release);
        tiles_published_.fetch_add(1, std::memory_order_release);
    }
}

void RenderLoop::merge_tile(size_t index, std::unique_ptr<ImageBlock> own) {
    const std::lock_guard<std::mutex> lock(merge_mutex_);
    finished_[index] = 1;
    waiting_[index] = std::move(own);
    merge_in_order(false);
}

// A pass cut short: the tiles that finished after one that did not, still in tile order.
void RenderLoop::merge_tiles_left() {
    const std::lock_guard<std::mutex> lock(merge_mutex_);
    merge_in_order(true);
}

// The finished tiles from next_merge_ on, in tile order, up to the first unfinished one (or past it).
void RenderLoop::merge_in_order(bool past_unfinished) {
    for (; next_merge_ < tiles_.size(); ++next_merge_) {
        if (!finished_[next_merge_]) {
            if (past_unfinished) continue;
            return;
        }
        pass_block_.merge(display_within_pass_ ? *tile_blocks_[next_merge_] : *waiting_[next_merge_]);
        waiting_[next_merge_].reset();
    }
}

void RenderLoop::show_between_passes() {
    const std::lock_guard<std::mutex> lock(display_mutex_);
    if (display_error_) std::rethrow_exception(display_error_);
    // A pass that was shown under way is shown at its end too, whenever that is: the frame between passes is
    // where on_display may read what the integrator learned (neepp view's map questions, which would
    // otherwise wait as long as frames within passes keep coming), and the pass took longer than the
    // interval, so the frame costs the render little.
    if (budget_.elapsed() - last_display_ < display_wait_ && shown_within_ != result_.passes - 1) return;
    const double start = budget_.elapsed();
    job_.on_display(DisplayFrame{current_image(), result_.spp, budget_.elapsed(), counted(), false, result_.spp,
                                 double(result_.spp), false});
    shown_passes_ = result_.passes;
    last_display_ = start;
    // Resolving the image is the render's time: a large image is shown less often, so that it costs at most
    // about 5 % of the render.
    display_wait_ = std::max(job_.display_interval_s, 20 * (budget_.elapsed() - start));
}

std::optional<DisplayFrame> RenderLoop::frame_within_pass(int &pass, size_t &tiles_shown) {
    std::optional<ImageBlock> samples;
    Image splat;
    DisplayFrame frame;
    uint64_t pixels_ahead = 0;  // pixels with the running pass's samples
    std::vector<size_t> finished;  // within the first pass: the tiles whose pixels have a sample
    bool first_pass = false;
    {
        const std::lock_guard<std::mutex> lock(pass_state_mutex_);
        const PassState &p = pass_state_;
        // Before the first pass is complete, a pixel of a tile not yet finished has no sample at all: shown
        // only to a caller that asked for it, which is told which pixels those are (NaN).
        if (!p.running || (p.passes == 0 && !display_first_pass_)) return std::nullopt;
        if (tiles_published_.load(std::memory_order_acquire) == (p.passes == pass ? tiles_shown : 0)) return std::nullopt;
        samples.emplace(accumulated_);
        size_t tiles = 0;
        for (size_t i = 0; i < tiles_.size(); ++i)
            if (tile_published_[i].load(std::memory_order_acquire)) {
                samples->merge(*tile_blocks_[i]);
                pixels_ahead += uint64_t(tiles_[i].w) * tiles_[i].h;
                ++tiles;
                if (p.passes == 0) finished.push_back(i);
            }
        first_pass = p.passes == 0;
        if (p.passes == pass && tiles == tiles_shown) return std::nullopt;
        pass = p.passes;
        tiles_shown = tiles;
        // A splatting integrator's image is two layers, each its own estimate of its share of the pixel:
        // the camera samples' (normalised by each pixel's weights) and the splats' (by the light paths).
        // The running pass's splats land anywhere while its tiles run, and its light paths are counted at
        // its end, so a frame within the pass has the completed passes' splats and the camera samples of
        // the finished tiles besides theirs: each layer still estimates its share, so the frame is a
        // correct, if unevenly sampled, image.
        if (splatting_ && light_paths_ > 0)
            splat = splats_accumulated_->resolve(double(W_) * H_ / light_paths_);
        frame.spp = p.spp;
        frame.spp_max = pixels_ahead > 0 ? p.spp + p.size : p.spp;
        frame.spp_mean = p.spp + p.size * (double(pixels_ahead) / (double(W_) * H_));
        frame.counters = p.counted;
    }
    frame.image = samples->resolve();
    if (first_pass) mark_unsampled(frame.image, tiles_, finished);
    if (!splat.data.empty())
        for (size_t i = 0; i < frame.image.data.size(); ++i) frame.image.data[i] += splat.data[i];
    frame.render_time_s = budget_.elapsed();
    frame.within_pass = true;
    return frame;
}

void RenderLoop::display_within_passes() {
    // Tiles finish at any time: with nothing new to show, look again a few times per interval.
    const auto poll = std::chrono::duration<double>(std::clamp(job_.display_interval_s / 4, 0.005, 0.05));
    int pass = -1;
    size_t tiles_shown = 0;
    std::unique_lock<std::mutex> lock(display_mutex_);
    while (!display_stop_) {
        const double due = last_display_ + display_wait_ - budget_.elapsed();
        if (due > 0) {
            display_wake_.wait_for(lock, std::chrono::duration<double>(due));
            continue;
        }
        lock.unlock();
        const double start = budget_.elapsed();
        const double cpu_start = cpu_seconds(CpuClock::thread);
        std::optional<DisplayFrame> frame = frame_within_pass(pass, tiles_shown);
        lock.lock();
        if (display_stop_) break;
        // Nothing new, or the render's thread has shown the end of this pass meanwhile (an image going back
        // would flicker).
        if (!frame || shown_passes_ > pass) {
            display_wake_.wait_for(lock, poll);
            continue;
        }
        try {
            job_.on_display(std::move(*frame));
            shown_within_ = pass;
        } catch (...) {  // raised by the render's thread
            display_error_ = std::current_exception();
            return;
        }
        last_display_ = start;
        // What a frame costs the render is the CPU time it takes from the workers (the image copied and
        // resolved, on_display): at most about 5 % of a core. Not its wall time, which on a machine that the
        // workers keep busy is mostly theirs.
        display_wait_ = std::max(job_.display_interval_s, 20 * (cpu_seconds(CpuClock::thread) - cpu_start));
    }
}

void RenderLoop::stop_display_thread() {
    if (!display_thread_.joinable()) return;
    {
        const std::lock_guard<std::mutex> lock(display_mutex_);
        display_stop_ = true;
    }
    display_wake_.notify_all();
    display_thread_.join();
}

void RenderLoop::merge_pass(uint64_t pass_light_paths) {
    accumulated_.merge(pass_block_);
    if (splatting_) {
        splats_accumulated_->merge(*splats_pass_);
        light_paths_ += double(pass_light_paths) + camera_sample_light_paths();
    }
}

RenderCheckpoint RenderLoop::make_checkpoint(const RenderCounters &counted_so_far) const {
    RenderCheckpoint c;
    c.spp = result_.spp;
    c.passes = result_.passes;
    c.render_time_s = budget_.elapsed();
    c.seconds_per_spp = seconds_per_spp_;
    c.light_paths = light_paths_;
    c.counters = counted_so_far;
    c.image_sums = accumulated_.sums();
    if (splatting_) c.splat_sums = splats_accumulated_->sums();
    c.integrator_state = integrator_.save_state();
    return c;
}

}  // namespace

RenderResult render(const Scene &scene, Integrator &integrator, const RenderJob &job) {
    return RenderLoop(scene, integrator, job).run();
}

Image image_from_sums(const Scene &scene, const std::vector<double> &image_sums, const std::vector<int64_t> &splat_sums,
                      double light_paths, double splat_scale) {
    const int W = scene.camera.width, H = scene.camera.height;
    ReconstructionFilter filter(scene.settings.rfilter, scene.settings.rfilter_radius, scene.settings.rfilter_stddev);
    ImageBlock image(0, 0, W, H, &filter);
    image.set_sums(image_sums);
    std::unique_ptr<SplatFilm> splats;
    if (!splat_sums.empty()) {
        splats = std::make_unique<SplatFilm>(W, H, &filter);
        splats->set_sums(splat_sums);
    }
    return combine_layers(image, splats.get(), light_paths, splat_scale);
}

}  // namespace neepp
