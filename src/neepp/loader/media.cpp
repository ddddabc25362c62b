// Mitsuba 3's participating media (<medium>) and phase functions (<phase>), and the scene's hold on them.
#include "neepp/loader/factories.h"
#include "neepp/loader/problems.h"
#include "neepp/media/homogeneous_medium.h"
#include "neepp/media/phase_functions.h"

namespace neepp::loader {

namespace {

std::shared_ptr<const PhaseFunction> make_phase(const XmlNode &node) {
    if (node.type == "isotropic") return std::make_shared<IsotropicPhase>();
    if (node.type == "hg") {
        // Mitsuba's default is 0.8, not 0: clouds and fog scatter forward.
        const float g = node.get_float("g", 0.8f, NumberRange{-1, 1, true, true});
        return std::make_shared<HenyeyGreensteinPhase>(g);
    }
    throw node.error("unsupported phase function '" + node.type + "' (supported: isotropic, hg)");
}

}  // namespace

const Medium *Factories::medium(const XmlNode &node) {
    if (auto it = media_.find(&node); it != media_.end()) return it->second.get();
    if (node.tag != "medium") throw node.error("expected a <medium>, found <" + node.tag + ">");
    if (node.type == "heterogeneous")
        throw node.error("heterogeneous media (density grids) are not supported yet; homogeneous media are");
    if (node.type != "homogeneous")
        throw node.error("unsupported medium '" + node.type + "' (supported: homogeneous)");
    std::shared_ptr<const PhaseFunction> phase;
    for (const auto &child : node.children) {
        if (child->tag == "phase") {
            if (phase) throw child->error("a medium has one phase function (this is its second)");
            phase = located_at(*child, [&] { return make_phase(*child); });
            warn_unused(*child);
        } else if (child->tag == "volume" || child->tag == "texture") {
            throw child->error("a medium's coefficients given as a volume or texture are not supported yet; give "
                               "sigma_t and albedo as <float>, <rgb> or <spectrum>");
        } else {
            throw child->error("unsupported inside a medium: <" + child->tag + ">");
        }
    }
    // As Mitsuba: an <rgb> coefficient lies in [0, 1] (scale sets the density), a <float> may be any
    // non-negative value.
    const Color sigma_t = node.get_rgb("sigma_t", Color(1.f));
    const Color albedo = node.get_rgb("albedo", Color(0.75f));
    const float scale = node.get_float("scale", 1.f, NumberRange::at_least(0));
    // Mitsuba's switch between two estimators of the same image; neepp always weighs each channel by its
    // own extinction (its spectral route), which is exact for grey media too.
    node.get_bool("has_spectral_extinction", true);
    auto m = std::make_shared<HomogeneousMedium>(sigma_t * scale, albedo);
    m->phase = phase ? phase : std::make_shared<IsotropicPhase>();
    m->sample_emitters = node.get_bool("sample_emitters", true);
    warn_unused(node);
    media_[&node] = m;
    return m.get();
}

void Factories::give_media_to(Scene &scene) const {
    for (const auto &[node, m] : media_) scene.add_medium(m);
}

}  // namespace neepp::loader
