// Integrator option parsing, as the CLI's --integrator and -I name=value reach it: the first line names
// the integrator, every further line is one option. An unknown name, a bad value or a conflict is an
// exception with a message; anything else is a bug. Constructing the integrator is all that runs (no
// scene), which covers every option's parsing and validation.
#include <exception>
#include <sstream>
#include "neepp/base/options.h"
#include "neepp/integrators/factory.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerInitialize(int *, char ***) {
    neepp::fuzz::write_seeds_if_asked([](const std::filesystem::path &dir) {
        neepp::fuzz::write_seed(dir, "path", "path\nmax_depth=5\nrr_depth=3\nhide_emitters=true\nnee=false\n");
        neepp::fuzz::write_seed(dir, "neepp", "path\nshadow_rays=neepp-adaptive\nvoxels=8\nsamples_per_pair=16\nq_min=0.1\n"
                                              "learn=true\nlearn_until=4\nlight_sampler=visibility\n");
        neepp::fuzz::write_seed(dir, "cv", "path\nshadow_rays=neepp-cv\nadaptive_target=0.5\nshadow_ray_cost=2\n"
                                           "min_occluded=0.3\nlight_sampler=bvh\n");
        neepp::fuzz::write_seed(dir, "bdpt", "bdpt\nlight_paths=neepp\ncandidates=8\npool=1024\nstrategy=2,2\n"
                                             "strategy_weight=none\nmis=balance\n");
        neepp::fuzz::write_seed(dir, "light", "light\nmax_depth=-1\n");
    });
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    std::istringstream in(std::string(reinterpret_cast<const char *>(data), size));
    std::string name, line;
    std::getline(in, name);
    neepp::Options options;
    while (std::getline(in, line))
        if (size_t eq = line.find('='); eq != std::string::npos && eq > 0) options.set(line.substr(0, eq), line.substr(eq + 1));
    try {
        neepp::make_integrator(name, options);
    } catch (const std::exception &) {
    }
    return 0;
}
