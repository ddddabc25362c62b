#include "neepp/render/render_loop.h"

#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include "neepp/integrators/integrator.h"
#include "neepp/math/denormals.h"
#include "neepp/render/film.h"
#include "neepp/render/memory.h"
#include "neepp/render/progress_bar.h"
#include "neepp/render/stats.h"
#include "neepp/sampling/sampler.h"
#include "neepp/scene/scene.h"

namespace neepp {
namespace {

using Clock = std::chrono::steady_clock;

// Camera samples handed to the integrator at once (Integrator::Li_batch).
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

// Samples per pass. The first is one sample per pixel: a whole image early (what Ctrl-C leaves if it comes
// soon) and a first measure of the speed. An integrator that learns between passes (NEE++'s map) then
// gets small passes, so that it learns early, growing geometrically (capped) so per-pass overhead stays
// negligible. One that does not gets full passes at once: a pixel's samples in a pass are consecutive, so
// each packet of 16 rays the path tracer traces then starts from one pixel, and coherent rays are cheaper
// to trace. Under a time limit a pass is sized to end before the deadline by the speed of the last
// (with a 5% margin): a pass is all or nothing, so one cut off by the deadline would be work thrown away.
int next_pass_size(int done, int target, double seconds_per_spp, double remaining_s, bool timed, bool learns) {
    constexpr int kMaxPass = 32;
    int size = done == 0 ? 1 : learns ? std::min(done, kMaxPass) : kMaxPass;
    if (target > 0) size = std::min(size, target - done);
    if (timed && seconds_per_spp > 0) {
        double affordable = std::floor(0.95 * remaining_s / seconds_per_spp);
        size = int(std::min<double>(size, affordable));
    }
    return size;
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


// The image: the accumulated samples plus the splat layer (if any), scaled by pixels / light paths.
Image combine_layers(const ImageBlock &samples, const SplatFilm *splats, double light_paths, double splat_scale) {
    Image image = samples.resolve();
    if (splats && light_paths > 0) {
        const Image splat = splats->resolve(double(image.width) * image.height / light_paths * splat_scale);
        for (size_t i = 0; i < image.data.size(); ++i) image.data[i] += splat.data[i];
    }
    return image;
}

}  // namespace

RenderResult render(const Scene &scene, Integrator &integrator, const RenderJob &job) {
    const Camera &cam = scene.camera;
    const int W = cam.width, H = cam.height;
    const bool timed = job.time_limit_s > 0;
    if (job.spp <= 0 && !timed) throw std::invalid_argument("render: give a sample count or a time limit");

    // Per pixel: the image and the pass (ImageBlock, 32 bytes each), the image resolved for the pass
    // statistics and for the result (12 each), the PNG's bytes (4); with splats, two splat films (24
    // bytes each) and the splat layer resolved (12).
    const bool splatting = integrator.splats();
    check_film_fits_in_memory(W, H, 2 * 32 + 2 * 12 + 4 + (splatting ? 2 * 24 + 12 : 0));
    ReconstructionFilter filter(scene.settings.rfilter, scene.settings.rfilter_radius, scene.settings.rfilter_stddev);
    const int border = int(std::ceil(filter.radius() - 0.5f));
    ImageBlock accumulated(0, 0, W, H, &filter), pass_block(0, 0, W, H, &filter);
    // Light tracing and BDPT splat anywhere on the film: a layer of its own, scaled by pixels / light paths.
    std::unique_ptr<SplatFilm> splats_accumulated, splats_pass;
    if (splatting) {
        splats_accumulated = std::make_unique<SplatFilm>(W, H, &filter);
        splats_pass = std::make_unique<SplatFilm>(W, H, &filter);
    }
    double light_paths = 0;
    std::mutex merge_mutex;
    std::vector<Tile> tiles = make_tiles(W, H, job.tile_size);
    const std::unique_ptr<Sampler> prototype = make_sampler(job.sampler, job.seed);

    int threads = job.threads > 0 ? job.threads : tbb::info::default_concurrency();
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    tbb::task_arena arena(threads);

    RenderResult result;
    tbb::enumerable_thread_specific<RenderCounters> counters;
    const Clock::time_point start = Clock::now();
    const double cpu_start = cpu_seconds(CpuClock::process);
    const double time_before = job.resume ? job.resume->render_time_s : 0.0;  // a resumed render's earlier time
    auto elapsed = [&] { return time_before + std::chrono::duration<double>(Clock::now() - start).count(); };

    std::vector<double> tile_m2(tiles.size());  // Σ lum(L)² per tile this pass, summed in tile order
    std::atomic<uint64_t> samples_done{0};  // camera samples completed this pass
    std::atomic<int> pass_size_now{0}, spp_done_now{0};
    auto fraction = [&]() -> double {
        if (timed && job.spp <= 0) return elapsed() / job.time_limit_s;
        double spp_done = spp_done_now.load() + double(samples_done.load()) / (double(W) * H);
        const int first = job.resume ? 0 : job.first_sample;
        double f = (spp_done - first) / double(job.spp - first);
        return timed ? std::max(f, elapsed() / job.time_limit_s) : f;
    };
    ProgressBar bar(fraction, job.progress, job.on_progress);

    integrator.prepare(scene);
    double seconds_per_spp = 0;
    RenderCounters counters_before;  // a resumed render's
    if (job.resume) {
        const RenderCheckpoint &c = *job.resume;
        if (splatting != !c.splat_sums.empty()) throw std::invalid_argument("resume: the checkpoint's splats do not match the integrator");
        accumulated.set_sums(c.image_sums);
        if (splatting) splats_accumulated->set_sums(c.splat_sums);
        light_paths = c.light_paths;
        result.spp = result.resumed_spp = c.spp;
        result.passes = c.passes;
        seconds_per_spp = c.seconds_per_spp;
        counters_before = c.counters;
        spp_done_now = result.spp;
        integrator.restore_state(scene, c.integrator_state);
    }
    if (!job.resume && job.first_sample > 0) {  // a range of sample indices (distributed rendering)
        if (job.spp <= job.first_sample) throw std::invalid_argument("render: the sample range is empty");
        result.spp = job.first_sample;
        spp_done_now = result.spp;
    }
    if (!job.resume && job.integrator_state) integrator.restore_state(scene, *job.integrator_state);
    auto current_image = [&] {
        return combine_layers(accumulated, splats_accumulated.get(), light_paths, integrator.splat_scale());
    };
    // Light paths the pass's camera samples splatted (an integrator's own pass body counts its own).
    auto camera_sample_light_paths = [&] {
        return integrator.renders_passes() ? 0.0 : integrator.light_paths_per_sample() * double(samples_done);
    };
    double last_checkpoint = elapsed(), last_snapshot = 0;
    bool checkpointed_at_stop = false;
    auto counted = [&] {
        RenderCounters sum = counters_before;
        for (const RenderCounters &t : counters) sum += t;
        return sum;
    };
    RenderCounters counted_at_pass_start;  // what a checkpoint of a pass cut short holds
    auto make_checkpoint = [&](const RenderCounters &counted_so_far) {
        RenderCheckpoint c;
        c.spp = result.spp;
        c.passes = result.passes;
        c.render_time_s = elapsed();
        c.seconds_per_spp = seconds_per_spp;
        c.light_paths = light_paths;
        c.counters = counted_so_far;
        c.image_sums = accumulated.sums();
        if (splatting) c.splat_sums = splats_accumulated->sums();
        c.integrator_state = integrator.save_state();
        return c;
    };
    auto checkpoint = [&](const RenderCounters &counted_so_far) {
        job.on_checkpoint(make_checkpoint(counted_so_far), current_image());
        last_checkpoint = elapsed();
    };
    for (;;) {
        if (job.cancel && job.cancel->load()) { result.stopped_by = "cancel"; break; }
        double remaining = timed ? job.time_limit_s - elapsed() : 0;
        if (timed && remaining <= 0) { result.stopped_by = "time"; break; }
        int size = next_pass_size(result.spp, job.spp, seconds_per_spp, remaining, timed,
                                  integrator.learns_between_passes());
        if (size <= 0) { result.stopped_by = (job.spp > 0 && result.spp >= job.spp) ? "spp" : "time"; break; }

        const int s0 = result.spp;
        if (job.on_checkpoint) counted_at_pass_start = counted();
        pass_block.clear();
        samples_done = 0;
        pass_size_now = size;
        std::atomic<bool> aborted{false};
        // A time limit cuts a pass short only when it overruns badly (the first pass, whose speed was
        // unknown, or a wrong estimate): otherwise the pass, sized to fit, is finished.
        auto must_stop = [&] {
            const bool overrun = timed && (result.passes == 0 ? elapsed() > job.time_limit_s
                                                              : elapsed() > 1.25 * job.time_limit_s);
            if ((job.cancel && job.cancel->load()) || overrun) aborted = true;
            return aborted.load(std::memory_order_relaxed);
        };
        const double pass_start = elapsed();
        // Light paths splatted apart from the camera samples (BDPT's NEE++ pool before the pass) or the
        // samples of an integrator's own pass body.
        uint64_t pass_light_paths = 0;
        double one_off_s = 0;
        const PassInfo info{result.passes, s0, size, uint64_t(W) * H * size, job.seed};
        if (splatting) {
            splats_pass->clear();
            if (!integrator.renders_passes())
                arena.execute([&] { pass_light_paths = integrator.begin_pass(scene, info, *splats_pass, counters.local()); });
        }
        if (integrator.renders_passes()) {
            const PassControl control{must_stop, &samples_done, &one_off_s};
            arena.execute([&] { pass_light_paths = integrator.render_pass(scene, info, *splats_pass, counters.local(), control); });
        } else arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t> &r) {
                const DenormalsAreZero ftz;
                // Samples go to the integrator in batches (see Integrator::Li_batch), each with its own sampler.
                std::vector<std::unique_ptr<Sampler>> owned;
                std::vector<Sampler *> samplers;
                for (int k = 0; k < kBatch; ++k) samplers.push_back(owned.emplace_back(prototype->clone()).get());
                std::vector<Ray> rays(kBatch);
                std::vector<Vec2> film_pos(kBatch);
                std::vector<Color> radiance(kBatch);
                RenderCounters &c = counters.local();
                for (size_t ti = r.begin(); ti != r.end(); ++ti) {
                    if (aborted.load(std::memory_order_relaxed) || must_stop()) return;
                    const Tile &t = tiles[ti];
                    double m2 = 0;
                    ImageBlock block(t.x0 - border, t.y0 - border, t.w + 2 * border, t.h + 2 * border, &filter);
                    int queued = 0;
                    auto add = [&](const Vec2 &pos, Color L) {
                        // Only NaN/inf are dropped: negative values are legitimate for unbiased
                        // estimators such as NEE++'s control variate and must average out.
                        if (!is_finite(L)) {
                            ++c.invalid_samples;
                            L = Color(0.f);
                        }
                        block.put(pos.x, pos.y, L);
                        m2 += double(luminance(L)) * double(luminance(L));
                    };
                    auto flush = [&] {
                        integrator.Li_batch(scene, std::span<const Ray>(rays.data(), queued),
                                            std::span<Sampler *const>(samplers.data(), queued),
                                            std::span<Color>(radiance.data(), queued), c);
                        for (int k = 0; k < queued; ++k) add(film_pos[k], radiance[k]);
                        queued = 0;
                    };
                    for (int y = t.y0; y < t.y0 + t.h; ++y)
                        for (int x = t.x0; x < t.x0 + t.w; ++x)
                            for (int s = s0; s < s0 + size; ++s) {
                                Sampler &sampler = *samplers[queued];
                                // Film pixels, so that a crop's pixels draw what the whole film's do.
                                sampler.start_sample(uint32_t(x + cam.crop_x), uint32_t(y + cam.crop_y), uint32_t(s));
                                Vec2 jitter = sampler.next_2d();
                                film_pos[queued] = Vec2(float(x) + jitter.x, float(y) + jitter.y);
                                // As Mitsuba: a lens's sample follows the film position's.
                                const Vec2 lens = cam.has_lens() ? sampler.next_2d() : Vec2(0.5f, 0.5f);
                                rays[queued] = cam.pixel_ray(x, y, jitter, lens);
                                if (splatting) {
                                    add(film_pos[queued], integrator.Li_splat(scene, rays[queued], sampler, c, *splats_pass));
                                    continue;
                                }
                                if (++queued == kBatch) flush();
                            }
                    if (queued > 0) flush();
                    tile_m2[ti] = m2;
                    samples_done += uint64_t(t.w) * t.h * size;
                    std::lock_guard<std::mutex> lock(merge_mutex);
                    pass_block.merge(block);
                }
            });
        });
        if (aborted) {
            // A checkpoint holds whole passes: the one cut short is not in it (nor in a resumed image).
            if (job.on_checkpoint && result.passes > 0) checkpoint(counted_at_pass_start);
            checkpointed_at_stop = true;
            // Keep a partial first pass rather than nothing at all: every pixel it reached is unbiased.
            if (result.passes == 0) {
                accumulated.merge(pass_block);
                if (splatting) {
                    splats_accumulated->merge(*splats_pass);
                    light_paths += double(pass_light_paths) + camera_sample_light_paths();
                }
            }
            result.stopped_by = (job.cancel && job.cancel->load()) ? "cancel" : "time";
            break;
        }
        accumulated.merge(pass_block);
        if (splatting) {
            splats_accumulated->merge(*splats_pass);
            light_paths += double(pass_light_paths) + camera_sample_light_paths();
        }
        result.spp += size;
        spp_done_now = result.spp;
        integrator.end_pass(scene, pass_statistics(result.passes, result.spp, size, tile_m2, accumulated));
        ++result.passes;
        seconds_per_spp = std::max(elapsed() - pass_start - one_off_s, 0.0) / size;
        if (job.on_snapshot && (last_snapshot == 0 || elapsed() >= job.snapshot_growth * last_snapshot)) {
            last_snapshot = elapsed();
            job.on_snapshot(result.spp, last_snapshot, current_image());
        }
        if (job.spp > 0 && result.spp >= job.spp) { result.stopped_by = "spp"; break; }
        if (job.on_checkpoint && elapsed() - last_checkpoint >= job.checkpoint_interval_s) checkpoint(counted());
    }
    // Stopped before its sample count between passes (time, Ctrl-C): what a resume continues from.
    if (job.on_checkpoint && result.stopped_by != "spp" && !checkpointed_at_stop && result.passes > 0) checkpoint(counted());
    pass_size_now = 0;
    bar.finish();

    result.render_time_s = elapsed();
    result.render_cpu_time_s = cpu_seconds(CpuClock::process) - cpu_start;
    result.counters = counted();
    result.occlusion_time_s = double(result.counters.occlusion_ticks) * seconds_per_tick();
    result.image = current_image();
    if (job.keep_state) result.state = make_checkpoint(result.counters);
    return result;
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
