// Mitsuba 3's participating media (<medium>) and phase functions (<phase>), and the scene's hold on them.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include "neepp/loader/factories.h"
#include "neepp/loader/problems.h"
#include "neepp/loader/supported_plugins.h"
#include "neepp/io/scene_error.h"
#include "neepp/io/vdb_reader.h"
#include "neepp/io/volume_grid_reader.h"
#include "neepp/media/blend_phase.h"
#include "neepp/media/heterogeneous_medium.h"
#include "neepp/media/homogeneous_medium.h"
#include "neepp/media/phase_functions.h"
#include "neepp/media/sggx_phase.h"
#include "neepp/media/tabulated_phase.h"

namespace neepp::loader {

namespace {

// The numbers of a string property, separated by spaces or commas, each finite as a float (as any number
// a scene gives) and, where `negative` is false, not below 0.
std::vector<float> numbers_in(const XmlNode &node, const std::string &prop, bool negative) {
    const std::string text = node.get_string(prop);
    std::vector<float> values;
    size_t at = 0;
    while ((at = text.find_first_not_of(" ,\t\n\r", at)) != std::string::npos) {
        const size_t end = text.find_first_of(" ,\t\n\r", at);
        const std::string token = text.substr(at, end == std::string::npos ? std::string::npos : end - at);
        at = end;
        char *stop = nullptr;
        const double v = std::strtod(token.c_str(), &stop);
        if (stop != token.c_str() + token.size())
            throw node.property_error(prop, "\"" + token + "\" is not a number");
        if (!std::isfinite(v) || std::abs(v) > std::numeric_limits<float>::max())
            throw node.property_error(prop, "\"" + token + "\" is not a finite number");
        if (v < 0 && !negative) throw node.property_error(prop, "\"" + token + "\" is negative: the values are a density");
        values.push_back(float(v));
    }
    return values;
}

// A constvolume of six values, a symmetric matrix: neepp's, as a string of numbers (Mitsuba 3's constvolume
// has no 6-channel lookup, so its sggx reads S from a gridvolume only).
std::shared_ptr<const Volume> constant_matrix_volume(const XmlNode &node) {
    const std::vector<float> v = numbers_in(node, "value", true);
    if (v.size() != 6)
        throw node.property_error("value", "a string value is a symmetric matrix, six numbers S_xx, S_yy, S_zz, S_xy, "
                                           "S_xz, S_yz (found " + std::to_string(v.size()) + ")");
    try {
        return std::make_shared<ConstantVolume>(SymmetricMatrix3::from_channels(v.data()), node.get_transform("to_world"));
    } catch (const std::invalid_argument &e) {
        throw node.property_error("value", e.what());
    }
}

// What a volume is read as where it is used: a colour (a medium's sigma_t and albedo, a blendphase's weight:
// grey, 1 channel, or RGB, 3) or a symmetric matrix (an sggx's S: 6 channels).
struct VolumeUse {
    std::string name;  // "a medium's sigma_t"
    bool matrix = false;
};

// Why a grid of `channels` channels does not fit its use, or empty when it does.
std::string channel_problem(uint32_t channels, const VolumeUse &use) {
    const std::string has = "the grid has " + std::to_string(channels) + (channels == 1 ? " channel; " : " channels; ");
    if (use.matrix)
        return channels == 6 ? "" : has + use.name + " is a symmetric matrix, 6 channels (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz)";
    if (channels == 1 || channels == 3) return "";
    return has + "a gridvolume's value is grey (1 channel) or RGB (3) as " + use.name +
           (channels == 6 ? " (6 channels hold a symmetric matrix, an sggx phase function's S)" : "");
}

// A <volume> (constvolume or gridvolume) as Mitsuba 3 reads it, for `use`.
std::shared_ptr<const Volume> make_volume(const XmlNode &node, const VolumeUse &use) {
    if (node.type == "constvolume") {
        const bool six = node.has("value") && node.props.at("value").kind == XmlProperty::Kind::String;
        if (six != use.matrix)
            throw node.property_error("value", six ? "six numbers are a symmetric matrix (an sggx's S), not " + use.name +
                                                         " (a <float>, <rgb> or <spectrum>)"
                                                   : use.name + " is a symmetric matrix: a string of six numbers S_xx, "
                                                                "S_yy, S_zz, S_xy, S_xz, S_yz");
        if (six) return constant_matrix_volume(node);
        return std::make_shared<ConstantVolume>(node.get_unbounded_rgb("value", Color(1.f)), node.get_transform("to_world"));
    }
    if (node.type != "gridvolume" && node.type != "grid")
        throw node.error("unsupported volume '" + node.type + "' (supported: constvolume, gridvolume)");
    GridVolumeOptions o;
    const std::string filter = node.get_string("filter_type", "trilinear");
    if (filter != "trilinear" && filter != "nearest")
        throw node.property_error("filter_type", "must be \"trilinear\" or \"nearest\"");
    o.filter = filter == "nearest" ? GridVolumeOptions::Filter::Nearest : GridVolumeOptions::Filter::Trilinear;
    const std::string wrap = node.get_string("wrap_mode", "clamp");
    if (wrap != "clamp" && wrap != "repeat" && wrap != "mirror")
        throw node.property_error("wrap_mode", "must be \"clamp\", \"repeat\" or \"mirror\"");
    o.wrap = wrap == "repeat" ? GridVolumeOptions::Wrap::Repeat
             : wrap == "mirror" ? GridVolumeOptions::Wrap::Mirror : GridVolumeOptions::Wrap::Clamp;
    o.to_world = node.get_transform("to_world");
    o.max_value = node.get_float("max_value", -1.f, NumberRange::above(0));  // -1: absent, the data's own
    node.get_bool("raw", false);   // the data is used as stored either way in RGB
    node.get_string("accel", "");  // Mitsuba's GPU texture option
    if (!node.has("filename")) throw node.error("a gridvolume needs a 'filename': its grid as a .vol or .vdb file");
    const std::string filename = node.get_string("filename");
    const std::string path = node.resolve_path(filename);
    const bool vdb = filename.size() >= 4 && filename.compare(filename.size() - 4, 4, ".vdb") == 0;
    if (!vdb) {
        o.use_grid_bbox = node.get_bool("use_grid_bbox", false);
        if (node.has("grid")) throw node.property_error("grid", "names a grid of a .vdb file; this gridvolume reads a .vol");
    } else if (!node.get_bool("use_grid_bbox", true)) {
        throw node.property_error("use_grid_bbox", "a .vdb grid is always placed by its own transform (as if "
                                                   "use_grid_bbox were true); to_world then places that in the scene");
    }
    const std::string grid_name = vdb ? node.get_string("grid", "") : "";
    try {  // the file's own error, located at the volume using it and naming its use
        VolumeGrid grid;
        if (vdb) {
            // A .vdb grid lives in its own world space (its voxels through its transform), which to_world
            // then places in the scene, as pbrt-v4's nanovdb medium places it by the current transform: the
            // identity leaves the file's coordinates as they are.
            VdbGrid g = read_vdb_grid(path, grid_name);  // its errors name the file
            o.to_world = o.to_world * g.unit_to_world;
            grid = std::move(g.grid);
        } else {
            grid = read_volume_grid(path);  // its errors name the file
            if (!grid.warning.empty()) warn(node.file, node.line, path + ": " + grid.warning);
        }
        // Whether its channels fit the use first: a colour's checks would refuse a matrix's negative entries.
        if (const std::string problem = channel_problem(grid.channels, use); !problem.empty()) throw SceneError(path, problem);
        try {
            return std::make_shared<GridVolume>(std::move(grid), o);
        } catch (const std::invalid_argument &e) {  // GridVolume's refusal of the values read
            throw SceneError(path, e.what());
        }
    } catch (const std::exception &e) {
        throw node.error((node.name.empty() ? "" : "as \"" + node.name + "\": ") + e.what());
    }
}

// Mitsuba's `tabphase` table: numbers separated by spaces or commas.
std::vector<float> tabulated_values(const XmlNode &node) {
    if (!node.has("values"))
        throw node.error("a tabphase needs its 'values': a string of numbers, the density at cosines evenly spaced "
                         "from -1 (backward) to 1 (forward)");
    const std::vector<float> values = numbers_in(node, "values", false);
    if (values.size() < 2)
        throw node.property_error("values", "needs at least two numbers (the density at cos_theta = -1 and 1)");
    if (std::all_of(values.begin(), values.end(), [](float v) { return v == 0.f; }))
        throw node.property_error("values", "all zero: there is no density to normalise");
    return values;
}

std::shared_ptr<const PhaseFunction> make_phase(const XmlNode &node) {
    if (node.type == "isotropic") return std::make_shared<IsotropicPhase>();
    if (node.type == "hg") {
        // Mitsuba's default is 0.8, not 0: clouds and fog scatter forward.
        const float g = node.get_float("g", 0.8f, NumberRange{-1, 1, true, true});
        return std::make_shared<HenyeyGreensteinPhase>(g);
    }
    if (node.type == "rayleigh") return std::make_shared<RayleighPhase>();
    if (node.type == "tabphase") return std::make_shared<TabulatedPhase>(tabulated_values(node));
    if (node.type == "sggx") {
        for (size_t i = 0; i < node.children.size(); ++i)
            if (node.children[i]->tag != "volume" || node.child_names[i] != "S")
                throw node.children[i]->error("an sggx holds one <volume> named \"S\", not a <" + node.children[i]->tag +
                                              "> named \"" + node.child_names[i] + "\"");
        const std::shared_ptr<XmlNode> child = node.child("S");
        if (!child)
            throw node.error("an sggx needs its 'S': a <volume> of 6 channels (S_xx, S_yy, S_zz, S_xy, S_xz, S_yz), the "
                             "microflakes' matrix (a gridvolume, or a constvolume whose value is a string of six numbers)");
        auto S = located_at(*child, [&] { return make_volume(*child, {"an sggx's S", true}); });
        warn_unused(*child);
        return std::make_shared<SGGXPhase>(S);
    }
    if (node.type == "blendphase") {
        std::vector<std::shared_ptr<const PhaseFunction>> nested;
        for (size_t i = 0; i < node.children.size(); ++i) {
            const XmlNode &child = *node.children[i];
            if (child.tag == "phase") {
                if (nested.size() == 2) throw child.error("a blendphase blends two phase functions (this is a third)");
                nested.push_back(located_at(child, [&] { return make_phase(child); }));
                warn_unused(child);
            } else if (child.tag == "volume") {
                if (node.child_names[i] != "weight")
                    throw child.error("a blendphase's volume is its \"weight\", not \"" + node.child_names[i] + "\"");
            } else {
                throw child.error("a blendphase holds two <phase> and a 'weight' (a <float> or a <volume>), not a <" +
                                  child.tag + ">");
            }
        }
        if (nested.size() != 2)
            throw node.error("a blendphase needs two nested <phase> (found " + std::to_string(nested.size()) + ")");
        // The second's share: a number or a volume, clipped to [0, 1] where it is read, as Mitsuba clips it
        // (so any finite number is accepted). Mitsuba has no default.
        std::shared_ptr<const Volume> weight;
        if (std::shared_ptr<XmlNode> child = node.child("weight")) {
            weight = located_at(*child, [&] { return make_volume(*child, {"a blendphase's weight"}); });
            warn_unused(*child);
        } else if (node.has("weight")) {
            weight = std::make_shared<ConstantVolume>(Color(node.get_float("weight")));
        } else {
            throw node.error("a blendphase needs its 'weight' (a <float> or a <volume>): the second phase function's share");
        }
        return std::make_shared<BlendPhase>(nested[0], nested[1], weight);
    }
    throw node.error("unsupported phase function '" + node.type + "' (supported: " + supported_list("phase") + ")");
}

}  // namespace

// A medium's coefficient `name`: a nested <volume>, or a <float>, <rgb> or <spectrum> (a constant volume).
std::shared_ptr<const Volume> Factories::volume_param(const XmlNode &node, const std::string &name, Color def) {
    if (std::shared_ptr<XmlNode> child = node.child(name)) {
        if (child->tag != "volume")
            throw child->error("a medium's '" + name + "' is a <volume>, a <float>, an <rgb> or a <spectrum>, not a <" +
                               child->tag + ">");
        auto v = located_at(*child, [&] { return make_volume(*child, {"a medium's " + name}); });
        warn_unused(*child);
        return v;
    }
    // As Mitsuba: an <rgb> coefficient lies in [0, 1] (scale sets the density), a <float> may be any
    // non-negative value.
    return std::make_shared<ConstantVolume>(node.get_rgb(name, def));
}

const Medium *Factories::medium(const XmlNode &node, bool used) {
    if (used) used_media_.insert(&node);
    if (auto it = media_.find(&node); it != media_.end()) return it->second.get();
    if (node.tag != "medium") throw node.error("expected a <medium>, found <" + node.tag + ">");
    if (node.type != "homogeneous" && node.type != "heterogeneous")
        throw node.error("unsupported medium '" + node.type + "' (supported: homogeneous, heterogeneous)");
    std::shared_ptr<const PhaseFunction> phase;
    for (size_t i = 0; i < node.children.size(); ++i) {
        const auto &child = node.children[i];
        if (child->tag == "phase") {
            if (phase) throw child->error("a medium has one phase function (this is its second)");
            phase = located_at(*child, [&] { return make_phase(*child); });
            warn_unused(*child);
        } else if (child->tag == "volume") {
            const std::string &name = node.child_names[i];
            if (name != "sigma_t" && name != "albedo")
                throw child->error("a medium's volumes are its \"sigma_t\" and \"albedo\", not \"" + name + "\"");
        } else {
            throw child->error("unsupported inside a medium: <" + child->tag + ">");
        }
    }
    const std::shared_ptr<const Volume> sigma_t = volume_param(node, "sigma_t", Color(1.f));
    const std::shared_ptr<const Volume> albedo = volume_param(node, "albedo", Color(0.75f));
    const float scale = node.get_float("scale", 1.f, NumberRange::at_least(0));
    // Mitsuba's switch between two estimators of the same image; neepp always weighs each channel by its
    // own extinction (its spectral route), which is exact for grey media too.
    node.get_bool("has_spectral_extinction", true);
    if (!phase) phase = std::make_shared<IsotropicPhase>();
    std::shared_ptr<Medium> m;
    if (node.type == "homogeneous") {
        if (!std::dynamic_pointer_cast<const ConstantVolume>(sigma_t))
            throw node.error("a homogeneous medium's sigma_t is one value (a <float>, <rgb>, <spectrum> or constvolume); "
                             "a grid of them makes a heterogeneous medium");
        // Its extinction is sigma_t times the flakes' projected area: the same everywhere only if S is.
        // (Mitsuba takes its majorant from S at the origin and would be biased wherever S differs.)
        if (const auto *sggx = dynamic_cast<const SGGXPhase *>(phase.get())) {
            const auto *grid = dynamic_cast<const GridVolume *>(&sggx->S());
            if (grid && !grid->uniform())
                throw node.error("a homogeneous medium's sggx S is the same everywhere (a constvolume, or a grid whose "
                                 "points all hold one matrix): S that varies makes the extinction vary, a heterogeneous medium");
        }
        m = std::make_shared<HomogeneousMedium>(sigma_t->eval(Vec3(0.f)) * scale, albedo, phase);
    } else {
        m = std::make_shared<HeterogeneousMedium>(sigma_t, albedo, scale, phase);
    }
    // Each is a float, their product need not be: an infinite extinction would make every free flight 0
    // long and every transmittance NaN.
    const float bound = max_component(sigma_t->max() * scale * Color(phase->max_projected_area()));
    if (!std::isfinite(bound))
        throw node.error("sigma_t times scale is not a finite number (the largest sigma_t " +
                         std::to_string(sigma_t->max()) + ", scale " + std::to_string(scale) + ")");
    m->sample_emitters = node.get_bool("sample_emitters", true);
    warn_unused(node);
    media_[&node] = m;
    return m.get();
}

void Factories::warn_unused_media() const {
    // Mitsuba renders such a scene as if the medium were not there; most likely a shape or the sensor was
    // meant to <ref> it.
    for (const auto &[node, m] : media_)
        if (!used_media_.count(node))
            warn(node->file, node->line, "this medium fills nothing: no shape names it as its interior or exterior "
                                         "and no sensor sits in it, so it changes no image");
}

void Factories::give_media_to(Scene &scene) const {
    for (const auto &[node, m] : media_)
        if (used_media_.count(node)) scene.add_medium(m);
}

}  // namespace neepp::loader
