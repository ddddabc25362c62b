// Every integrator's options, with their defaults and what they mean: `neepp list`, the -I help of
// `neepp render --help` and the README's tables are made from it, and tests/integrators/test_option_table.cpp
// checks it against what make_integrator reads, so it cannot drift from the code.
#pragma once
#include <string>
#include <vector>

namespace neepp {

struct OptionDoc {
    std::string name;
    std::string default_value;  // as -I spells it; "" when unset means "none"
    std::string description;
    // Another option's setting without which it is not read, e.g. "shadow_rays=neepp-adaptive" ("neepp*": any
    // value starting so).
    std::string needs;
};

struct IntegratorDoc {
    std::string name;
    std::string description;
    std::vector<OptionDoc> options;
};

// path, bdpt, light, pssmlt, in that order.
const std::vector<IntegratorDoc> &integrator_docs();
// The shadow-ray policies (shadow_rays=...) with one line each.
const std::vector<std::pair<std::string, std::string>> &shadow_ray_policy_docs();

}  // namespace neepp
