#include <algorithm>
#include <set>
#include <fmt/core.h>
#include "neepp/integrators/factory.h"
#include "neepp/loader/factories.h"
#include "neepp/loader/supported_plugins.h"

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

// Mitsuba 3's integrators and their equivalent here. volpathmis estimates what volpath does (it weighs
// the channels' and the strategies' densities together, which changes the noise only); prb and prb_basic are path
// tracers written for differentiation (prb_projective too); direct (and direct_projective, "prb_projective
// with max_depth 2" in Mitsuba's docs) is next event estimation and BSDF sampling at the first hit only,
// which path with max_depth 2 is; ptracer is particle tracing, neepp's light.
const std::map<std::string, Mapping> &mitsuba_integrators() {
    static const std::map<std::string, Mapping> m = {
        {"prb", {"path", -2, {}}},
        {"prb_basic", {"path", -2, {}}},
        {"volpathmis", {"volpath", -2, {}}},
        {"direct", {"path", 2, {"emitter_samples", "bsdf_samples", "shading_samples"}}},
        {"ptracer", {"light", -2, {"samples_per_pass"}}},
        // The projective-sampling integrators differ from prb and direct in their derivatives only; their
        // own options size and guide the derivative estimates.
        {"prb_projective", {"path", -2, {"sppc", "sppp", "sppi", "guiding", "guiding_proj", "guiding_rounds"}}},
        {"direct_projective", {"path", 2, {"sppc", "sppp", "sppi", "guiding", "guiding_proj", "guiding_rounds"}}},
    };
    return m;
}

// Integrators that wrap others and write more beside the image, which is their first nested
// integrator's (Mitsuba makes it their RGB image): moment adds the second moments of each nested
// integrator, aov arbitrary output variables of the visible surfaces. neepp writes the image only.
// Mitsuba nests sampling integrators only: ptracer (which splats) it refuses. Each with what it writes
// beside the image.
const std::map<std::string, std::string> kWrappers = {
    {"moment", "the second-moment channels"},
    {"aov", "the AOV channels"},
};

// The AOV types of Mitsuba's aov integrator (src/integrators/aov.cpp).
const std::set<std::string> kAovTypes = {"albedo",     "depth",     "position", "uv",     "geo_normal", "sh_normal",
                                         "dp_du",      "dp_dv",     "duv_dx",   "duv_dy", "prim_index", "shape_index"};

// The aov integrator's `aovs` string, "name:type" pairs separated by commas or spaces, checked as Mitsuba
// checks it (it refuses the integrator without one, or with an unknown type): the pairs, for the note.
std::vector<std::string> aov_channels(const XmlNode &aov) {
    if (!aov.has("aovs"))
        throw aov.error("the 'aov' integrator needs its string 'aovs' (\"name:type, ...\"), as in Mitsuba");
    const std::string spec = aov.get_string("aovs");
    std::vector<std::string> pairs;
    size_t i = 0;
    while ((i = spec.find_first_not_of(", ", i)) != std::string::npos) {
        const size_t end = spec.find_first_of(", ", i);
        const std::string pair = spec.substr(i, end == std::string::npos ? std::string::npos : end - i);
        i = end;
        const size_t colon = pair.find(':');
        if (colon == 0 || colon == std::string::npos || pair.find(':', colon + 1) != std::string::npos)
            throw aov.error("'aovs': '" + pair + "' is not a name:type pair");
        if (!kAovTypes.count(pair.substr(colon + 1))) {
            std::string types;
            for (const std::string &t : kAovTypes) types += (types.empty() ? "" : ", ") + t;
            throw aov.error("'aovs': unknown AOV type '" + pair.substr(colon + 1) + "' in '" + pair + "' (Mitsuba's: " +
                            types + ")");
        }
        pairs.push_back(pair);
    }
    return pairs;
}

// The integrator a wrapper takes its image from, and a clause naming what it writes that neepp does not.
const XmlNode &unwrap(const XmlNode &wrapper, std::string &not_written) {
    std::vector<std::pair<const XmlNode *, std::string>> nested;  // with the name each was given
    for (size_t k = 0; k < wrapper.children.size(); ++k)
        if (wrapper.children[k]->tag == "integrator")
            nested.push_back({wrapper.children[k].get(), wrapper.child_names[k]});
    const std::string &extra = kWrappers.at(wrapper.type);
    std::string what = extra;
    if (wrapper.type == "aov") {
        std::string channels;
        for (const std::string &c : aov_channels(wrapper)) channels += (channels.empty() ? "" : ", ") + c;
        if (!channels.empty()) what += " (" + channels + ")";
    }
    for (auto &[name, prop] : wrapper.props) prop.used = true;  // its options shape its extra outputs only
    if (nested.empty())
        throw wrapper.error("the '" + wrapper.type + "' integrator nests no integrator: Mitsuba's image is then black, "
                            "beside " + extra + ", which neepp does not write; nest the integrator that renders "
                            "the image (e.g. <integrator type=\"path\"/>)");
    for (const auto &[n, name] : nested)
        if (n->type == "ptracer")
            throw n->error("Mitsuba's '" + wrapper.type + "' integrator nests sampling integrators only, not 'ptracer' "
                           "(render the scene with ptracer alone)");
    if (nested.size() > 1) {
        std::string others;
        for (size_t k = 1; k < nested.size(); ++k)
            others += (others.empty() ? "'" : ", '") + (nested[k].second.empty() ? nested[k].first->type : nested[k].second) + "'";
        what += " and the images of its other nested integrators (" + others + ")";
    }
    not_written += (not_written.empty() ? "" : "; ") + ("'" + wrapper.type + "': " + what);
    return *nested[0].first;
}

}  // namespace

void load_integrator(const XmlNode &node, RenderSettings &settings) {
    const XmlNode *n = &node;
    std::string chain, not_written;
    while (kWrappers.count(n->type)) {
        chain += "'" + n->type + "' around ";
        n = &unwrap(*n, not_written);
    }
    const std::vector<std::string> &known = supported_names("integrator");
    if (std::find(known.begin(), known.end(), n->type) == known.end() && !integrator_registered(n->type))
        throw n->error("unsupported integrator '" + n->type + "' (supported: " + supported_list("integrator") + ")");
    // Mitsuba 3's bounds for the depths every path-building integrator reads (an integer of another kind is
    // refused by the integrator's options).
    if (n->has("max_depth") && n->props.at("max_depth").kind == XmlProperty::Kind::Integer)
        n->get_int("max_depth", -1, NumberRange::at_least(-1));
    if (n->has("rr_depth") && n->props.at("rr_depth").kind == XmlProperty::Kind::Integer)
        n->get_int("rr_depth", 5, NumberRange::at_least(1));
    settings.integrator = n->type;
    settings.integrator_options.clear();
    const auto mapped = mitsuba_integrators().find(n->type);
    std::vector<std::string> dropped;
    for (auto &[name, prop] : n->props) {
        prop.used = true;
        if (mapped != mitsuba_integrators().end() && mapped->second.noise_only.count(name)) {
            // Sample counts: Mitsuba 3 reads them unsigned.
            if (prop.kind == XmlProperty::Kind::Integer) n->get_int(name, 0, NumberRange::at_least(0));
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
    fmt::print(stderr, "neepp: note: {}:{}: Mitsuba's integrator {}'{}' renders here as '{}'{}, the same image{}{}\n",
               node.file, node.line, chain, n->type, settings.integrator, how,
               ignored.empty() ? "" : " (" + ignored + " change only the noise: ignored)",
               not_written.empty() ? "" : "; not written: " + not_written);
}

}  // namespace neepp::loader
