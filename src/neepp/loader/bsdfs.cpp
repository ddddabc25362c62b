#include <cmath>
#include <optional>
#include "neepp/loader/supported_plugins.h"
#include "neepp/loader/factories.h"
#include "neepp/loader/plugins.h"
#include "neepp/materials/blendbsdf.h"
#include "neepp/materials/bumpmap.h"
#include "neepp/materials/conductor.h"
#include "neepp/materials/dielectric.h"
#include "neepp/materials/diffuse.h"
#include "neepp/materials/hair.h"
#include "neepp/materials/ior.h"
#include "neepp/materials/normalmap.h"
#include "neepp/materials/plastic.h"
#include "neepp/materials/principled.h"
#include "neepp/materials/principledthin.h"
#include "neepp/materials/roughconductor.h"
#include "neepp/materials/roughdielectric.h"
#include "neepp/materials/pplastic.h"
#include "neepp/materials/roughplastic.h"
#include "neepp/materials/thindielectric.h"
#include "neepp/materials/mask.h"
#include "neepp/materials/null.h"
#include "neepp/materials/twosided.h"

namespace neepp::loader {
namespace {

MicrofacetType distribution_param(const XmlNode &node) {
    std::string name = node.get_string("distribution", "beckmann");
    auto t = parse_microfacet_type(name);
    if (!t) throw node.error("unknown microfacet distribution '" + name + "' (beckmann, ggx)");
    return *t;
}

// Mitsuba's microfacet roughness: `alpha`, or both `alpha_u` and `alpha_v` (anisotropic), each a float or
// a texture; 0.1 when none is given.
std::pair<TexturePtr, TexturePtr> roughness_params(Factories &f, const XmlNode &node) {
    const bool has_u = node.has("alpha_u") || node.child("alpha_u"), has_v = node.has("alpha_v") || node.child("alpha_v");
    if (!has_u && !has_v) {
        TexturePtr a = f.texture_param(node, "alpha", Color(0.1f), true);
        return {a, a};
    }
    if (!has_u || !has_v) throw node.error("give both 'alpha_u' and 'alpha_v'");
    if (node.has("alpha") || node.child("alpha")) throw node.error("give either 'alpha' or 'alpha_u'/'alpha_v'");
    return {f.texture_param(node, "alpha_u", Color(0.1f), true), f.texture_param(node, "alpha_v", Color(0.1f), true)};
}

// Mitsuba's conductor parameters: a named `material` or explicit `eta`/`k`.
std::pair<TexturePtr, TexturePtr> conductor_ior(Factories &f, const XmlNode &node) {
    std::string material = node.get_string("material", "none");
    // Without a material, eta and k are read with Mitsuba's defaults (those of "none"), so that a k given
    // alone is read (and checked) as Mitsuba reads it.
    if (node.has("eta") || node.child("eta") || material == "none") {
        if (material != "none") throw node.error("give either 'material' or 'eta'/'k', not both");
        return {f.texture_param(node, "eta", Color(0.f), true), f.texture_param(node, "k", Color(1.f), true)};
    }
    auto ior = lookup_conductor_ior(material);
    if (!ior) throw node.error("unknown conductor material '" + material + "'");
    return {constant_texture(ior->eta), constant_texture(ior->k)};
}

}  // namespace

// Mitsuba's principled: a lobe parameter the scene leaves out, or gives as the float 0, switches its lobe
// off (null); anything else, a texture included, switches it on.
TexturePtr Factories::principled_lobe_param(const XmlNode &node, const std::string &name) {
    if (node.has(name) && node.props.at(name).kind == XmlProperty::Kind::Float && node.get_float(name) == 0.f)
        return nullptr;
    return texture_param_or_null(node, name);
}

PrincipledParams Factories::principled_params(const XmlNode &node) {
    PrincipledParams p;
    p.base_color = texture_param(node, "base_color", Color(0.5f));
    p.roughness = texture_param(node, "roughness", Color(0.5f));
    p.anisotropic = principled_lobe_param(node, "anisotropic");
    p.metallic = principled_lobe_param(node, "metallic");
    p.spec_trans = principled_lobe_param(node, "spec_trans");
    p.spec_tint = principled_lobe_param(node, "spec_tint");
    p.sheen = principled_lobe_param(node, "sheen");
    p.sheen_tint = principled_lobe_param(node, "sheen_tint");
    p.flatness = principled_lobe_param(node, "flatness");
    p.clearcoat = principled_lobe_param(node, "clearcoat");
    // Read whether or not there is a clearcoat, as Mitsuba does (it is then merely unused).
    p.clearcoat_gloss = texture_param(node, "clearcoat_gloss", Color(0.f));
    if (node.has("eta") && node.has("specular")) throw node.error("give either 'eta' or 'specular', not both");
    if (node.has("eta")) {
        p.eta = node.get_float("eta", 1.5f, NumberRange::above(0));
        // A transmissive interface of IOR 1 is degenerate: Mitsuba moves it off 1.
        if (p.spec_trans && p.eta == 1.f) p.eta = 1.001f;
    } else {
        // 12.5 would make the IOR infinite.
        float specular = node.get_float("specular", 0.5f, NumberRange{0, 12.5, false, true});
        if (p.spec_trans && specular == 0.f) specular = 1e-3f;
        p.eta = principled_eta_from_specular(specular);
    }
    const NumberRange rate = NumberRange::at_least(0);
    p.main_specular_sampling_rate = node.get_float("main_specular_sampling_rate", 1.f, rate);
    p.clearcoat_sampling_rate = node.get_float("clearcoat_sampling_rate", 1.f, rate);
    p.diffuse_reflectance_sampling_rate = node.get_float("diffuse_reflectance_sampling_rate", 1.f, rate);
    if (!(p.main_specular_sampling_rate > 0.f))
        throw node.error("'main_specular_sampling_rate' must be positive (the specular lobes would never be sampled)");
    return p;
}

PrincipledThinParams Factories::principled_thin_params(const XmlNode &node) {
    PrincipledThinParams p;
    p.base_color = texture_param(node, "base_color", Color(0.5f));
    p.roughness = texture_param(node, "roughness", Color(0.5f));
    p.eta = texture_param(node, "eta", Color(1.5f), true);
    p.anisotropic = principled_lobe_param(node, "anisotropic");
    p.spec_trans = principled_lobe_param(node, "spec_trans");
    p.spec_tint = principled_lobe_param(node, "spec_tint");
    p.sheen = principled_lobe_param(node, "sheen");
    p.sheen_tint = principled_lobe_param(node, "sheen_tint");
    p.flatness = principled_lobe_param(node, "flatness");
    p.diff_trans = principled_lobe_param(node, "diff_trans");
    const NumberRange rate = NumberRange::at_least(0);
    p.specular_reflectance_sampling_rate = node.get_float("specular_reflectance_sampling_rate", 1.f, rate);
    p.specular_transmittance_sampling_rate = node.get_float("specular_transmittance_sampling_rate", 1.f, rate);
    p.diffuse_reflectance_sampling_rate = node.get_float("diffuse_reflectance_sampling_rate", 1.f, rate);
    p.diffuse_transmittance_sampling_rate = node.get_float("diffuse_transmittance_sampling_rate", 1.f, rate);
    if (!(p.diffuse_reflectance_sampling_rate > 0.f))
        throw node.error("'diffuse_reflectance_sampling_rate' must be positive (the diffuse lobe would never be sampled)");
    return p;
}

// Mitsuba's hair: pigment concentrations or an absorption texture (scaled by `scale`), not both.
HairParams Factories::hair_params(const XmlNode &node) {
    HairParams p;
    const NumberRange roughness{0, 1, true, false};
    p.longitudinal_roughness = node.get_float("longitudinal_roughness", p.longitudinal_roughness, roughness);
    p.azimuthal_roughness = node.get_float("azimuthal_roughness", p.azimuthal_roughness, roughness);
    p.scale_tilt_deg = node.get_float("scale_tilt", p.scale_tilt_deg);
    const float int_ior = ior_param(node, "int_ior", 1.55f), ext_ior = ior_param(node, "ext_ior", 1.000277f);
    if (int_ior == ext_ior) throw node.error("'int_ior' and 'ext_ior' must differ");
    p.eta = int_ior / ext_ior;
    // Read whichever absorption is used, as Mitsuba does (a scale beside pigments is then merely unused).
    p.sigma_a_scale = node.get_float("scale", 1.f, NumberRange::at_least(0));
    const bool pigments = node.has("eumelanin") || node.has("pheomelanin");
    if (node.has("sigma_a") || node.child("sigma_a")) {
        if (pigments) throw node.error("give either 'sigma_a' or the pigments 'eumelanin'/'pheomelanin', not both");
        p.sigma_a = texture_param(node, "sigma_a", Color(0.f), true);
    } else {
        const float eumelanin = node.get_float("eumelanin", 1.3f, NumberRange::at_least(0)),
                    pheomelanin = node.get_float("pheomelanin", 0.2f, NumberRange::at_least(0));
        if (!std::isfinite(eumelanin + pheomelanin)) throw node.error("pigment concentrations must be finite");
        p.sigma_a = constant_texture(hair_pigment_absorption(eumelanin, pheomelanin));
        p.sigma_a_scale = 1.f;
    }
    return p;
}

float ior_param(const XmlNode &node, const std::string &name, float def) {
    if (!node.has(name)) return def;
    const XmlProperty &p = node.props.at(name);
    if (p.kind == XmlProperty::Kind::String) {
        std::string s = node.get_string(name);
        auto v = lookup_dielectric_ior(s);
        if (!v) throw node.error("unknown index of refraction '" + s + "' for '" + name + "'");
        return *v;
    }
    return node.get_float(name, def, NumberRange::above(0));
}

BSDFPtr Factories::default_bsdf() {
    if (!default_bsdf_) default_bsdf_ = std::make_shared<DiffuseBSDF>(constant_texture(0.5f));
    return default_bsdf_;
}

BSDFPtr Factories::black_bsdf() {
    if (!black_bsdf_) black_bsdf_ = std::make_shared<DiffuseBSDF>(constant_texture(0.f));
    return black_bsdf_;
}

BSDFPtr Factories::bsdf(const XmlNode &node) {
    if (auto it = bsdfs_.find(&node); it != bsdfs_.end()) return it->second;
    if (node.tag != "bsdf") throw node.error("expected a <bsdf>, found <" + node.tag + ">");
    BSDFPtr b;
    try {
        b = create_bsdf(node);
    } catch (const SceneError &) {
        throw;
    } catch (const std::exception &e) {  // a constructor's validation, located at its element
        throw node.error(e.what());
    }
    // How many BSDFs it evaluates at each shading point: a blend evaluates both of its own, a wrapper one.
    // Blends of blends of one shared BSDF double it at every level, so a file could make each shading
    // point cost 2^depth evaluations: a render that never ends.
    int cost = 1;
    if (const auto nested = node.children_with_tag("bsdf"); !nested.empty()) {
        cost = 0;
        for (const auto &child : nested) {
            const int c = bsdf_cost_.count(child.get()) ? bsdf_cost_.at(child.get()) : 1;
            cost = node.type == "blendbsdf" ? cost + c : std::max(cost, c);
        }
    }
    if (cost > kMaxBsdfEvaluations)
        throw node.error("this BSDF evaluates " + std::to_string(cost) + " nested BSDFs at every shading point "
                         "(blendbsdfs of blendbsdfs); at most " + std::to_string(kMaxBsdfEvaluations));
    bsdf_cost_[&node] = cost;
    warn_unused(node);
    bsdfs_[&node] = b;
    return b;
}

BSDFPtr Factories::create_bsdf(const XmlNode &node) {
    const std::string &t = node.type;
    auto nested = [&](size_t count_min, size_t count_max) {
        auto kids = node.children_with_tag("bsdf");
        if (kids.size() < count_min || kids.size() > count_max)
            throw node.error("needs " + std::to_string(count_min) + (count_max > count_min ? " or " + std::to_string(count_max) : "") +
                             " nested <bsdf>, found " + std::to_string(kids.size()));
        return kids;
    };
    BSDFPtr b;
    if (t == "diffuse") {
        b = std::make_shared<DiffuseBSDF>(texture_param(node, "reflectance", Color(0.5f)));
    } else if (t == "twosided") {
        auto kids = nested(1, 2);
        b = std::make_shared<TwoSidedBSDF>(bsdf(*kids[0]), kids.size() > 1 ? bsdf(*kids[1]) : nullptr);
    } else if (t == "null") {
        b = std::make_shared<NullBSDF>();
    } else if (t == "polarizer") {
        // The polarizer's angle changes nothing for unpolarized light: read only so that it is not "unused".
        if (auto theta = node.child("theta")) texture(*theta);
        else node.get_unbounded_rgb("theta", Color(0.f), ColorRange::Signed);
        b = std::make_shared<NullBSDF>(texture_param(node, "transmittance", Color(1.f)), 0.5f);
    } else if (t == "mask") {
        auto kids = nested(1, 1);
        b = std::make_shared<MaskBSDF>(texture_param(node, "opacity", Color(0.5f)), bsdf(*kids[0]));
    } else if (t == "bumpmap") {
        auto kids = nested(1, 1);
        auto tex = node.children_with_tag("texture");
        if (tex.size() != 1) throw node.error("needs exactly one nested <texture> (the height map)");
        b = std::make_shared<BumpMapBSDF>(texture(*tex[0]), node.get_float("scale", 1.f), bsdf(*kids[0]),
                                          node.get_bool("flip_invalid_normals", true),
                                          node.get_bool("use_shadowing_function", true));
    } else if (t == "normalmap") {
        auto kids = nested(1, 1);
        TexturePtr normals = texture_param_or_null(node, "normalmap");
        if (!normals) throw node.error("needs a texture named 'normalmap' (the tangent-space normals)");
        b = std::make_shared<NormalMapBSDF>(normals, bsdf(*kids[0]), node.get_bool("flip_invalid_normals", true),
                                            node.get_bool("use_shadowing_function", true));
    } else if (t == "blendbsdf") {
        auto kids = nested(2, 2);
        TexturePtr weight = texture_param_or_null(node, "weight");
        if (!weight) throw node.error("needs a 'weight' (a float or a texture: 0 gives the first BSDF, 1 the second)");
        b = std::make_shared<BlendBSDF>(weight, bsdf(*kids[0]), bsdf(*kids[1]));
    } else if (t == "conductor") {
        auto [eta, k] = conductor_ior(*this, node);
        b = std::make_shared<ConductorBSDF>(eta, k, texture_param_or_null(node, "specular_reflectance"));
    } else if (t == "roughconductor") {
        auto [eta, k] = conductor_ior(*this, node);
        auto [au, av] = roughness_params(*this, node);
        b = std::make_shared<RoughConductorBSDF>(distribution_param(node), au, av, eta, k,
                                                 texture_param_or_null(node, "specular_reflectance"),
                                                 node.get_bool("sample_visible", true));
    } else if (t == "plastic") {
        b = std::make_shared<PlasticBSDF>(ior_param(node, "int_ior", 1.49f), ior_param(node, "ext_ior", 1.000277f),
                                          texture_param(node, "diffuse_reflectance", Color(0.5f)),
                                          texture_param_or_null(node, "specular_reflectance"),
                                          node.get_bool("nonlinear", false));
    } else if (t == "roughplastic") {
        b = std::make_shared<RoughPlasticBSDF>(distribution_param(node), node.get_float("alpha", 0.1f, NumberRange::at_least(0)),
                                               ior_param(node, "int_ior", 1.49f), ior_param(node, "ext_ior", 1.000277f),
                                               texture_param(node, "diffuse_reflectance", Color(0.5f)),
                                               texture_param_or_null(node, "specular_reflectance"),
                                               node.get_bool("nonlinear", false), node.get_bool("sample_visible", true));
    } else if (t == "pplastic") {
        auto [au, av] = roughness_params(*this, node);
        float eta;
        if (node.has("eta")) {
            if (node.has("int_ior") || node.has("ext_ior")) throw node.error("give either 'eta' or 'int_ior'/'ext_ior', not both");
            eta = node.get_float("eta", 1.5f, NumberRange::above(0));
        } else {
            eta = ior_param(node, "int_ior", 1.49f) / ior_param(node, "ext_ior", 1.000277f);
        }
        if (!(eta > 0.f) || eta == 1.f) throw node.error("the interior and exterior indices of refraction must be positive and differ");
        b = std::make_shared<PolarizedPlasticBSDF>(distribution_param(node), au, av, eta,
                                                   texture_param(node, "diffuse_reflectance", Color(0.5f)),
                                                   texture_param_or_null(node, "specular_reflectance"),
                                                   node.get_bool("sample_visible", true));
    } else if (t == "dielectric" || t == "thindielectric") {
        float int_ior = ior_param(node, "int_ior", 1.5046f), ext_ior = ior_param(node, "ext_ior", 1.000277f);
        TexturePtr r = texture_param_or_null(node, "specular_reflectance");
        TexturePtr tr = texture_param_or_null(node, "specular_transmittance");
        if (t == "dielectric") b = std::make_shared<DielectricBSDF>(int_ior, ext_ior, r, tr);
        else b = std::make_shared<ThinDielectricBSDF>(int_ior, ext_ior, r, tr);
    } else if (t == "roughdielectric") {
        auto [au, av] = roughness_params(*this, node);
        const float int_ior = ior_param(node, "int_ior", 1.5046f), ext_ior = ior_param(node, "ext_ior", 1.000277f);
        if (int_ior == ext_ior) throw node.error("'int_ior' and 'ext_ior' must differ");
        b = std::make_shared<RoughDielectricBSDF>(distribution_param(node), au, av, int_ior, ext_ior,
                                                  texture_param_or_null(node, "specular_reflectance"),
                                                  texture_param_or_null(node, "specular_transmittance"),
                                                  node.get_bool("sample_visible", true));
    } else if (t == "hair") {
        b = std::make_shared<HairBSDF>(hair_params(node));
    } else if (t == "principled") {
        b = std::make_shared<PrincipledBSDF>(principled_params(node));
    } else if (t == "principledthin") {
        b = std::make_shared<PrincipledThinBSDF>(principled_thin_params(node));
    } else if (const BSDFPlugin *plugin = find_bsdf_plugin(t)) {
        b = (*plugin)(PluginProperties(node, *this));
        if (!b) throw node.error("the '" + t + "' plugin built no BSDF");
    } else {
        throw node.error("unsupported BSDF type '" + t + "' (supported: " + supported_list("bsdf") + ")");
    }
    return b;
}

}  // namespace neepp::loader
