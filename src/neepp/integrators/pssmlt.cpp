#include "neepp/integrators/pssmlt.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include "neepp/io/binary_io.h"
#include "neepp/math/distribution.h"
#include "neepp/render/film.h"
#include "neepp/scene/scene.h"

namespace neepp {

namespace {

// Seeds of the bootstrap samples' numbers and of the chains' own, apart from each other and from the
// render's other samplers.
constexpr uint64_t kBootstrapStream = 0x626f6f7473747261ULL;
constexpr uint64_t kChainStream = 0x636861696e737472ULL;
// Mutations a chain makes between looks at the render loop's stop signal and progress counter.
constexpr int kMutationsPerCheck = 64;

// The inner integrator's splats, kept for the chain to weigh.
class ContributionList final : public SplatSink {
public:
    explicit ContributionList(std::vector<PSSMLTIntegrator::Contribution> &out) : out_(out) {}
    bool add(float px, float py, const Color &L) override {
        if (!is_finite(L)) return false;
        out_.push_back({Vec2(px, py), L});
        return true;
    }

private:
    std::vector<PSSMLTIntegrator::Contribution> &out_;
};

void record(SplatFilm &film, const std::vector<PSSMLTIntegrator::Contribution> &c, float scale) {
    for (const PSSMLTIntegrator::Contribution &k : c) film.add(k.raster.x, k.raster.y, k.L * scale);
}

}  // namespace

PSSMLTIntegrator::PSSMLTIntegrator(PSSMLTOptions options, std::unique_ptr<Integrator> inner,
                                   std::unique_ptr<Integrator> volumetric)
    : options_(options), plain_(std::move(inner)), volumetric_(std::move(volumetric)) {
    if (volumetric_) use_inner(volumetric_.get());  // refused here, not at the first scene with media
    use_inner(plain_.get());
}

void PSSMLTIntegrator::use_inner(Integrator *inner) {
    inner_ = inner;
    inner_rays_ = dynamic_cast<const RayIntegrator *>(inner);
    inner_splats_ = dynamic_cast<const SplattingIntegrator *>(inner);
    if (!inner_rays_ && !inner_splats_) throw std::invalid_argument("pssmlt: the inner integrator must render per sample");
}

void PSSMLTIntegrator::prepare(const Scene &scene) {
    if (scene.has_media() && !volumetric_)
        throw std::invalid_argument("pssmlt: participating media are not supported by its bidirectional chains; "
                                    "render this scene with pssmlt over volpath (bidirectional=false) or with volpath");
    use_inner(scene.has_media() ? volumetric_.get() : plain_.get());
    inner_->prepare(scene);
    chains_.clear();
    bootstrapped_ = map_changed_ = false;
    f_sum_ = pass_f_sum_ = 0;
    f_samples_ = pass_f_samples_ = 0;
    mutations_ = accepted_ = large_steps_ = large_accepted_ = zero_proposals_ = 0;
}

float PSSMLTIntegrator::evaluate(const Scene &scene, PrimarySampleSpaceSampler &sampler, std::vector<Contribution> &out,
                                 RenderCounters &counters) const {
    out.clear();
    sampler.start_evaluation();
    const Camera &cam = scene.camera;
    // The film position and lens point, as the render loop draws them: the first numbers of the camera stream.
    const Vec2 u = sampler.next_2d();
    const Vec2 lens = cam.has_lens() ? sampler.next_2d() : Vec2(0.5f, 0.5f);
    const Ray ray = cam.generate_ray(u, lens);
    ContributionList splats(out);
    Color L;
    if (inner_splats_) {
        L = inner_splats_->Li(scene, ray, sampler, counters, splats);
    } else {  // the inner integrator's own form: the fast one where it has one, a batch of this one ray
        Sampler *const samplers[1] = {&sampler};
        Li_batch(*inner_rays_, scene, std::span<const Ray>(&ray, 1), samplers, std::span<Color>(&L, 1), counters);
    }
    if (is_finite(L)) out.push_back({Vec2(u.x * float(cam.width), u.y * float(cam.height)), L});
    else ++counters.invalid_samples;
    float f = 0;
    for (const Contribution &c : out) f += std::max(luminance(c.L), 0.f);
    return std::isfinite(f) ? f : 0.f;
}

bool PSSMLTIntegrator::bootstrap(const Scene &scene, const PassInfo &pass, RenderCounters &counters,
                                 const PassControl &control) {
    const size_t N = size_t(options_.bootstrap);
    std::vector<float> f(N);
    tbb::enumerable_thread_specific<RenderCounters> local;
    std::atomic<bool> stopped{false};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, N, 256), [&](const tbb::blocked_range<size_t> &r) {
        if (stopped || control.stop()) {
            stopped = true;
            return;
        }
        PrimarySampleSpaceSampler sampler(options_.sigma, options_.large_step);
        std::vector<Contribution> c;
        RenderCounters &rc = local.local();
        for (size_t i = r.begin(); i != r.end(); ++i) {
            sampler.restart(pass.seed ^ kBootstrapStream, i);
            f[i] = evaluate(scene, sampler, c, rc);
        }
    });
    for (const RenderCounters &c : local) counters += c;
    if (stopped) return false;
    double sum = 0;  // in index order: the same b for any thread count
    for (float v : f) sum += v;
    f_sum_ = sum, f_samples_ = N;
    chains_.assign(size_t(options_.chains), Chain{PrimarySampleSpaceSampler(options_.sigma, options_.large_step), {}, 0});
    if (normalization() > 0) {
        // Each chain starts from a bootstrap sample drawn in proportion to f, its numbers replayed, then
        // continues on numbers of its own (chains that start alike part at their first mutation).
        const Distribution1D pick(f);
        tbb::enumerable_thread_specific<RenderCounters> local2;
        tbb::parallel_for(tbb::blocked_range<size_t>(0, chains_.size(), 16), [&](const tbb::blocked_range<size_t> &r) {
            RenderCounters &rc = local2.local();
            for (size_t k = r.begin(); k != r.end(); ++k) {
                Chain &chain = chains_[k];
                PCG32 rng(mix_bits(pass.seed ^ kChainStream), mix_bits(k));
                const uint32_t i = pick.sample_discrete(rng.next_float());
                chain.sampler.restart(pass.seed ^ kBootstrapStream, i);
                chain.f = evaluate(scene, chain.sampler, chain.current, rc);
                chain.sampler.reseed(pass.seed ^ kChainStream, k);
            }
        });
        for (const RenderCounters &c : local2) counters += c;
    }
    bootstrapped_ = true;
    return true;
}

uint64_t PSSMLTIntegrator::render_pass(const Scene &scene, const PassInfo &pass, SplatFilm &splats,
                                       RenderCounters &counters, const PassControl &control) {
    if (bootstrapped_) chains_at_pass_start_ = encode_chains();
    in_pass_ = bootstrapped_;
    if (!bootstrapped_) {
        const auto start = std::chrono::steady_clock::now();
        const bool done = bootstrap(scene, pass, counters, control);
        if (control.one_off_s) *control.one_off_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (!done) return 0;
    }
    const uint64_t total = pass.camera_samples;
    if (!(normalization() > 0)) {  // no sample found light: the image is black, every mutation would record nothing
        *control.samples_done += total;
        return total;
    }
    const size_t n = chains_.size();
    tbb::enumerable_thread_specific<RenderCounters> local;
    std::atomic<uint64_t> recorded{0}, accepted{0}, large{0}, large_accepted{0}, zero{0};
    std::vector<double> large_f(n, 0.0);  // per chain, summed in chain order: the same for any thread count
    const bool reevaluate = map_changed_;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1), [&](const tbb::blocked_range<size_t> &r) {
        RenderCounters &rc = local.local();
        std::vector<Contribution> proposal;
        for (size_t k = r.begin(); k != r.end(); ++k) {
            Chain &chain = chains_[k];
            // The target changed with the map: the current state's f and contributions are the new ones.
            if (reevaluate) chain.f = evaluate(scene, chain.sampler, chain.current, rc);
            const uint64_t m = total / n + (k < total % n ? 1 : 0);
            uint64_t done = 0, acc = 0, lg = 0, lg_acc = 0, z = 0;
            while (done < m) {
                if (control.stop()) break;
                const uint64_t chunk = std::min<uint64_t>(kMutationsPerCheck, m - done);
                for (uint64_t j = 0; j < chunk; ++j) {
                    const bool large_step = chain.sampler.propose();
                    const float f = evaluate(scene, chain.sampler, proposal, rc);
                    const float a = chain.f > 0 ? std::min(1.f, f / chain.f) : 1.f;
                    if (a > 0 && f > 0) record(splats, proposal, a / f);
                    if (a < 1 && chain.f > 0) record(splats, chain.current, (1.f - a) / chain.f);
                    if (large_step) large_f[k] += double(f);  // an independent sample of f: refines b
                    lg += large_step;
                    z += !(f > 0);
                    if (chain.sampler.uniform() < a) {
                        chain.sampler.accept();
                        chain.current.swap(proposal);
                        chain.f = f;
                        ++acc;
                        lg_acc += large_step;
                    } else {
                        chain.sampler.reject();
                    }
                }
                done += chunk;
                *control.samples_done += chunk;
            }
            recorded += done, accepted += acc, large += lg, large_accepted += lg_acc, zero += z;
        }
    });
    for (const RenderCounters &c : local) counters += c;
    map_changed_ = false;
    mutations_ += recorded, accepted_ += accepted, large_steps_ += large, large_accepted_ += large_accepted;
    zero_proposals_ += zero;
    pass_f_sum_ = 0;
    for (double v : large_f) pass_f_sum_ += v;
    pass_f_samples_ = large;
    return recorded;
}

void PSSMLTIntegrator::end_pass(const Scene &scene, const PassStatistics &pass) {
    // Asked before: the pass that ends the learning publishes a map too.
    const bool learning = inner_->learns_between_passes();
    inner_->end_pass(scene, pass);
    map_changed_ = map_changed_ || learning;
    in_pass_ = false;
    // The pass's large steps join b's estimate once the pass is in the image (one cut short is not).
    f_sum_ += pass_f_sum_, f_samples_ += pass_f_samples_;
    pass_f_sum_ = 0, pass_f_samples_ = 0;
}

std::string PSSMLTIntegrator::encode_chains() const {
    BinaryWriter out;
    out.put(uint8_t(bootstrapped_)), out.put(uint8_t(map_changed_));
    out.put(f_sum_), out.put(f_samples_);
    out.put(mutations_), out.put(accepted_), out.put(large_steps_), out.put(large_accepted_), out.put(zero_proposals_);
    out.put(uint64_t(chains_.size()));
    for (const Chain &c : chains_) {
        c.sampler.save(out);
        out.put(c.f);
        out.put_vector(c.current);
    }
    return out.bytes;
}

std::string PSSMLTIntegrator::save_state() const {
    BinaryWriter out;
    out.put_string(inner_->save_state());
    out.put_string(in_pass_ ? chains_at_pass_start_ : encode_chains());
    return out.bytes;
}

void PSSMLTIntegrator::restore_state(const Scene &scene, const std::string &state) {
    BinaryReader in{state, 0, "pssmlt checkpoint state"};
    inner_->restore_state(scene, in.get_string());
    const std::string chains = in.get_string();
    BinaryReader c{chains, 0, "pssmlt checkpoint state"};
    bootstrapped_ = c.get<uint8_t>() != 0, map_changed_ = c.get<uint8_t>() != 0;
    f_sum_ = c.get<double>(), f_samples_ = c.get<uint64_t>();
    mutations_ = c.get<uint64_t>(), accepted_ = c.get<uint64_t>(), large_steps_ = c.get<uint64_t>();
    large_accepted_ = c.get<uint64_t>(), zero_proposals_ = c.get<uint64_t>();
    const uint64_t n = c.get<uint64_t>();
    if (bootstrapped_ && n != uint64_t(options_.chains))
        throw std::runtime_error("pssmlt checkpoint state: it holds " + std::to_string(n) + " chains, not " +
                                 std::to_string(options_.chains));
    chains_.assign(size_t(n), Chain{PrimarySampleSpaceSampler(options_.sigma, options_.large_step), {}, 0});
    for (Chain &chain : chains_) {
        chain.sampler.load(c);
        chain.f = c.get<float>();
        chain.current = c.get_vector<Contribution>();
    }
    in_pass_ = false;
}

nlohmann::json PSSMLTIntegrator::describe() const {
    return {{"name", "pssmlt"},
            {"bidirectional", options_.bidirectional},
            {"bootstrap", options_.bootstrap},
            {"chains", options_.chains},
            {"large_step", options_.large_step},
            {"sigma", options_.sigma},
            {"over", inner_->describe()}};
}

nlohmann::json PSSMLTIntegrator::statistics() const {
    nlohmann::json j = {{"normalization", normalization()},
                        {"normalization_samples", f_samples_},
                        {"mutations", mutations_},
                        {"acceptance", mutations_ ? double(accepted_) / double(mutations_) : 0.0},
                        {"large_steps", large_steps_},
                        {"large_step_acceptance", large_steps_ ? double(large_accepted_) / double(large_steps_) : 0.0},
                        {"zero_proposals", zero_proposals_}};
    if (nlohmann::json s = inner_->statistics(); !s.empty()) j["over"] = s;
    return j;
}

}  // namespace neepp
