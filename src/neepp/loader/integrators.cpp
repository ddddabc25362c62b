#include <set>
#include <fmt/core.h>
#include "neepp/loader/factories.h"

namespace neepp::loader {

namespace {

// A property as the integrator options' key=value string (empty for kinds an option cannot be).
std::string option_value(const XmlProperty &p) {
    switch (p.kind) {
    case XmlProperty::Kind::Integer: return std::to_string(p.i);
    case XmlProperty::Kind::Float: return fmt::format("{}", p.f);
    case XmlProperty::Kind::Boolean: return p.b ? "true" : "false";
    case XmlProperty::Kind::String: return p.s;
    default: return {};
    }
}

struct Mapping {
    const char *neepp;           // the integrator of neepp that renders the same image
    int max_depth;               // forced max_depth, or -2 to keep the scene's
    std::set<std::string> noise_only;  // options that change only the noise (sample counts): dropped
};

// Mitsuba 3's integrators and their equivalent here. Without participating media (which neepp refuses
// where a scene declares them) volpath and volpathmis trace what path does; prb and prb_basic are path
// tracers written for differentiation; direct is next event estimation and BSDF sampling at the first
// hit only, which path with max_depth 2 is; ptracer is particle tracing, neepp's light.
const std::map<std::string, Mapping> &mitsuba_integrators() {
    static const std::map<std::string, Mapping> m = {
        {"prb", {"path", -2, {}}},
        {"prb_basic", {"path", -2, {}}},
        {"volpath", {"path", -2, {}}},
        {"volpathmis", {"path", -2, {}}},
        {"direct", {"path", 2, {"emitter_samples", "bsdf_samples", "shading_samples"}}},
        {"ptracer", {"light", -2, {"samples_per_pass"}}},
    };
    return m;
}

// Integrators that only wrap another and change what is output beside its image (moment adds the
// second moment as extra channels): the image is the nested integrator's.
const std::set<std::string> kWrappers = {"moment"};

}  // namespace

void load_integrator(const XmlNode &node, RenderSettings &settings) {
    const XmlNode *n = &node;
    std::string chain;
    while (kWrappers.count(n->type)) {
        const auto nested = n->children_with_tag("integrator");
        if (nested.size() != 1)
            throw n->error("the '" + n->type + "' integrator wraps one integrator here, found " +
                           std::to_string(nested.size()));
        chain += "'" + n->type + "' around ";
        for (auto &[name, prop] : n->props) prop.used = true;  // its own options shape its extra outputs only
        n = nested[0].get();
    }
    settings.integrator = n->type;
    settings.integrator_options.clear();
    const auto mapped = mitsuba_integrators().find(n->type);
    std::vector<std::string> dropped;
    for (auto &[name, prop] : n->props) {
        prop.used = true;
        if (mapped != mitsuba_integrators().end() && mapped->second.noise_only.count(name)) {
            dropped.push_back(name);
            continue;
        }
        const std::string v = option_value(prop);
        if (v.empty()) throw n->error("integrator option '" + name + "' must be a number, boolean or string");
        settings.integrator_options[name] = v;
    }
    if (mapped == mitsuba_integrators().end() && chain.empty()) return;
    std::string how;
    if (mapped != mitsuba_integrators().end()) {
        settings.integrator = mapped->second.neepp;
        if (mapped->second.max_depth != -2) {
            settings.integrator_options["max_depth"] = std::to_string(mapped->second.max_depth);
            how = fmt::format(" with max_depth {}", mapped->second.max_depth);
        }
    }
    std::string ignored;
    for (const std::string &d : dropped) ignored += (ignored.empty() ? "" : ", ") + d;
    fmt::print(stderr, "neepp: note: {}:{}: Mitsuba's integrator {}'{}' renders here as '{}'{}, the same image{}\n",
               node.file, node.line, chain, n->type, settings.integrator, how,
               ignored.empty() ? "" : " (" + ignored + " change only the noise: ignored)");
}

}  // namespace neepp::loader
