// `-I neepp=auto`: which of NEE++'s uses pays on a scene is measured on it, not guessed. Each candidate
// (plain NEE, and each choice between lights by voxel, with and without the map, on scenes with several
// lights; with auto_guiding, path guiding by the SD-tree on any scene) is prepared and renders the
// same pilot: a few samples of pixels spread over the film, with the same random numbers. Its efficiency
// is 1 / (relative variance per sample × CPU time per sample); the render goes on with the most efficient,
// and with plain NEE unless another beats it by a margin, so that the pilot's own noise cannot pick a
// loser. The statistics list every candidate's figures and say what was picked and why.
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include "neepp/base/integrator.h"

namespace neepp {

struct AutoCandidate {
    std::string name;                    // "nee", "light-visibility", ...
    std::map<std::string, std::string> overrides;  // options set on top of the user's
    std::function<bool(const Scene &)> applies;    // whether it can differ from plain NEE on the scene
    // Pilot passes it renders and learns from (end_pass after each) before it is measured: one for a light
    // choice (its tables built, its first decisions taken), more for a guide, which learns from its passes.
    int warm_up_passes = 1;
};

// The candidates of `neepp=auto` for the path integrator; the first is plain NEE. guiding
// (-I auto_guiding=true): practical path guiding's too ("guided"), which applies on every scene, so that
// even a scene with one light then runs a pilot.
const std::vector<AutoCandidate> &auto_candidates(bool guiding = false);

struct AutoPilotResult {
    std::string name;
    double relative_variance = 0;  // per sample: mean over the pilot pixels of Var / (mean² + 0.01), of luminance
    double seconds_per_sample = 0;  // CPU time
    double efficiency = 0;          // relative to plain NEE's
    double prepare_s = 0;           // wall time to build its tables and map, and of the unmeasured first pilot pass
};

class AutoIntegrator final : public RayIntegrator {
public:
    using Make = std::function<std::unique_ptr<RayIntegrator>(const AutoCandidate &)>;
    // make: builds a candidate's integrator (its maps are built by its prepare, only if it applies).
    AutoIntegrator(std::vector<AutoCandidate> candidates, Make make);

    // Efficiency a candidate must reach, relative to plain NEE, to be picked.
    static constexpr double kMargin = 1.15;
    // Pilot size: pixels on a grid of up to kPilotGrid × kPilotGrid, kPilotSpp samples each per pass, one
    // pass to warm up and kPilotPasses measured.
    static constexpr int kPilotGrid = 48;
    static constexpr int kPilotSpp = 8;
    static constexpr int kPilotPasses = 4;

    void prepare(const Scene &scene) override;
    Color Li(const Scene &scene, const Ray &ray, Sampler &sampler, RenderCounters &counters) const override {
        return chosen().Li(scene, ray, sampler, counters);
    }
    const RayBatch *batch() const override { return chosen().batch(); }
    void end_pass(const Scene &scene, const PassStatistics &pass) override { chosen().end_pass(scene, pass); }
    bool learns_between_passes() const override { return chosen().learns_between_passes(); }
    // The state starts with the pick, so that a resumed render, and every worker of a distributed one,
    // continues with the candidate the first picked (the pilot's timing differs from machine to machine).
    std::string save_state() const override;
    void restore_state(const Scene &scene, const std::string &state) override;
    std::string merge_states(const std::string &base, const std::vector<std::string> &learned) const override;
    nlohmann::json describe() const override;
    nlohmann::json statistics() const override;

    const std::string &picked() const { return candidates_[chosen_].name; }
    const std::vector<AutoPilotResult> &pilot() const { return pilot_; }

private:
    RayIntegrator &chosen() const { return *chosen_integrator_; }
    void choose(const Scene &scene, size_t k);  // builds and prepares candidate k unless it is the one held
    std::vector<AutoCandidate> candidates_;
    Make make_;
    std::unique_ptr<RayIntegrator> chosen_integrator_;
    size_t chosen_ = 0;
    std::vector<AutoPilotResult> pilot_;
    std::string why_;
};

}  // namespace neepp
