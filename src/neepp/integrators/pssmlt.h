// Primary-sample-space Metropolis light transport (Kelemen, Szirmay-Kalos, Antal & Csonka 2002) over
// bidirectional path tracing, or over the path tracer (bidirectional=false).
//
// One sample of the inner integrator is a deterministic function of the uniform numbers it reads
// (PrimarySampleSpaceSampler): the film position, then its subpaths, connections and roulettes, each on
// a stream of its own. Its contributions (to its pixel and, for BDPT, splats anywhere) are the vector
// c(u), and f(u) = Σ luminance is the target a Markov chain on u samples in proportion to. A bootstrap of
// N independent samples estimates b = ∫ f du; each of n chains starts from a bootstrap sample drawn in
// proportion to f (so it starts in the stationary distribution) and proposes mutations, large steps
// (every number afresh) with probability large_step and small ones (normal offsets of size sigma)
// otherwise, accepted with probability a = min(1, f(u') / f(u)). Each mutation records both states,
// the proposal weighted by a and the current one by 1 - a (Veach's expected-value recording), each
// contribution divided by f: the image is pixels · b · E[c / f] over the chain, so a sample's splat,
// as a light path's, is normalized by pixels / samples, and the splat layer is scaled by b. A large
// step's proposal is an independent uniform sample: its f refines b (Kelemen et al. §4), so the image's
// brightness does not stay at the bootstrap's error. `--spp` counts mutations per pixel.
//
// NEE++'s shadow-ray policies work inside the chain: a roulette's number is part of u, on its stream, so
// the 1/q weights are part of f. When the visibility map changes between passes, f changes with it:
// each chain's current state is evaluated again before the next pass. The control-variate policy
// (whose estimate can be negative) and BDPT's NEE++ light-path selection (its pool, traced anew every
// pass, is not a function of u) are refused.
#pragma once
#include <memory>
#include <vector>
#include "neepp/base/integrator.h"
#include "neepp/sampling/primary_sample_space.h"

namespace neepp {

struct PSSMLTOptions {
    bool bidirectional = true;
    int bootstrap = 100000;     // N: independent samples estimating b and seeding the chains
    int chains = 1024;          // n
    float large_step = 0.3f;    // probability that a mutation is a large step
    float sigma = 0.01f;        // standard deviation of a small step's offset of each number
};

class PSSMLTIntegrator final : public PassIntegrator {
public:
    // volumetric: what the chains run over in scenes with participating media (volpath where inner is
    // path), or null where inner has no such form (bdpt): such scenes are then refused.
    PSSMLTIntegrator(PSSMLTOptions options, std::unique_ptr<Integrator> inner,
                     std::unique_ptr<Integrator> volumetric = nullptr);
    void prepare(const Scene &scene) override;
    uint64_t render_pass(const Scene &scene, const PassInfo &pass, SplatFilm &splats, RenderCounters &counters,
                         const PassControl &control) override;
    void end_pass(const Scene &scene, const PassStatistics &pass) override;
    bool learns_between_passes() const override { return inner_->learns_between_passes(); }
    // The chains (as the last complete pass left them), b and the inner integrator's state.
    std::string save_state() const override;
    void restore_state(const Scene &scene, const std::string &state) override;
    nlohmann::json describe() const override;
    nlohmann::json statistics() const override;

    // A sample's contribution at a film position (raster coordinates).
    struct Contribution {
        Vec2 raster;
        Color L;
    };
    // One sample of the inner integrator from the sampler's numbers: its contributions in `out`, f(u)
    // returned. Public for tests.
    float evaluate(const Scene &scene, PrimarySampleSpaceSampler &sampler, std::vector<Contribution> &out,
                   RenderCounters &counters) const;
    // b, the mean of f over its samples so far (0 before the bootstrap).
    double normalization() const { return f_samples_ > 0 ? f_sum_ / double(f_samples_) : 0.0; }
    // The splats are c / f: the image is them times b, whose estimate improves as the render goes.
    double splat_scale() const override { return normalization(); }

private:
    struct Chain {
        PrimarySampleSpaceSampler sampler;
        std::vector<Contribution> current;
        float f = 0;
    };
    // Estimates b and starts the chains; false when stopped before it finished.
    bool bootstrap(const Scene &scene, const PassInfo &pass, RenderCounters &counters, const PassControl &control);

    std::string encode_chains() const;

    PSSMLTOptions options_;
    std::unique_ptr<Integrator> plain_, volumetric_;
    Integrator *inner_;  // the one of the two the scene prepared for needs
    // inner_ as its family: one of the two is set (read once here, not at every sample).
    const RayIntegrator *inner_rays_ = nullptr;
    const SplattingIntegrator *inner_splats_ = nullptr;
    void use_inner(Integrator *inner);
    std::vector<Chain> chains_;
    // The chains as the pass under way found them: a pass cut short is not in a checkpoint (the render
    // loop keeps whole passes), so neither are its mutations.
    std::string chains_at_pass_start_;
    bool in_pass_ = false;
    bool bootstrapped_ = false;
    bool map_changed_ = false;  // the inner integrator learned since the chains' states were evaluated
    // b: the mean of f over the bootstrap and every large step of the completed passes (each an
    // independent uniform sample of u), so the image's brightness converges as its noise does.
    double f_sum_ = 0, pass_f_sum_ = 0;
    uint64_t f_samples_ = 0, pass_f_samples_ = 0;
    uint64_t mutations_ = 0, accepted_ = 0, large_steps_ = 0, large_accepted_ = 0, zero_proposals_ = 0;
};

}  // namespace neepp
