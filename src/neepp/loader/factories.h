// Internal to the loader: builders from XML nodes to renderer objects, sharing one cache so that a node
// referenced many times (a BSDF used by many shapes) becomes one object.
#pragma once
#include <map>
#include <set>
#include <memory>
#include "neepp/base/bsdf.h"
#include "neepp/io/xml_tree.h"
#include "neepp/materials/hair.h"
#include "neepp/materials/principled.h"
#include "neepp/materials/principledthin.h"
#include "neepp/media/volume.h"
#include "neepp/scene/scene.h"

namespace neepp::loader {

class Factories {
public:
    TexturePtr texture(const XmlNode &node);
    // The parameter `name` of node as a texture: a nested texture, an rgb/float/spectrum constant, or def.
    // unbounded: a spectrum is not clamped to [0, 1] (Mitsuba's get_unbounded_texture, e.g. a conductor's eta).
    TexturePtr texture_param(const XmlNode &node, const std::string &name, Color def, bool unbounded = false);
    TexturePtr texture_param_or_null(const XmlNode &node, const std::string &name, bool unbounded = false);
    BSDFPtr bsdf(const XmlNode &node);
    BSDFPtr default_bsdf();
    BSDFPtr black_bsdf();  // an emitter's default
    // Creates the shape (and its area light, if any) and adds both to the scene. A `shapegroup` adds
    // nothing (its shapes are built for the instances); an `instance` adds placed copies of its group's.
    void shape(const XmlNode &node, Scene &scene);
    void emitter(const XmlNode &node, Scene &scene);
    // A <medium> (made once however many shapes name it); the scene holds it after give_media_to.
    // `used`: a shape or the sensor names it (false: only declared, at the top level).
    const Medium *medium(const XmlNode &node, bool used = true);
    // Warns of each medium that was declared but that no shape bounds and no sensor sits in.
    void warn_unused_media() const;
    std::shared_ptr<const Volume> volume_param(const XmlNode &node, const std::string &name, Color def);
    void give_media_to(Scene &scene) const;

private:
    // The shape in world space with its BSDF; emitter_node is set to its <emitter>, null when none.
    std::unique_ptr<Shape> build_shape(const XmlNode &node, const XmlNode *&emitter_node);
    // A shapegroup's shapes (each in its own to_world), built at the first use and shared by every
    // instance of the group (loader/instances.cpp).
    const std::vector<std::unique_ptr<Shape>> &shape_group(const XmlNode &node);
    void instance(const XmlNode &node, Scene &scene);
    BSDFPtr create_bsdf(const XmlNode &node);
    TexturePtr principled_lobe_param(const XmlNode &node, const std::string &name);
    PrincipledParams principled_params(const XmlNode &node);
    PrincipledThinParams principled_thin_params(const XmlNode &node);
    HairParams hair_params(const XmlNode &node);
    std::map<const XmlNode *, TexturePtr> textures_;
    std::map<const XmlNode *, BSDFPtr> bsdfs_;
    // Nested BSDFs each built BSDF evaluates per shading point (Factories::bsdf), and their bound.
    static constexpr int kMaxBsdfEvaluations = 64;
    std::map<const XmlNode *, int> bsdf_cost_;
    std::map<const XmlNode *, std::vector<std::unique_ptr<Shape>>> shape_groups_;
    BSDFPtr default_bsdf_, black_bsdf_;
    std::map<const XmlNode *, std::shared_ptr<const Medium>> media_;
    std::set<const XmlNode *> used_media_;
};

// f(), with any error it throws that does not say where (a plugin's, a constructor's) located at node.
template <typename F> auto located_at(const XmlNode &node, F &&f) -> decltype(f()) {
    try {
        return f();
    } catch (const SceneError &) {
        throw;
    } catch (const std::exception &e) {
        throw node.error(e.what());
    }
}

// The scene's <integrator>: its type and options, with Mitsuba 3's integrators mapped to the one here
// that renders the same image (prb, volpath without media, direct, ptracer, the moment wrapper), said
// in one line on stderr.
void load_integrator(const XmlNode &node, RenderSettings &settings);
// Throws, naming the shape, when a mesh_attribute texture under bsdf_node reads an attribute the shape
// lacks (Mitsuba fails at render time; here it fails at load).
void check_mesh_attributes(const XmlNode &bsdf_node, const Shape &shape, const XmlNode &shape_node);
// Reports properties that no builder read (misspelt or unsupported) on stderr, as Mitsuba does.
void warn_unused(const XmlNode &node);
// A perspective projection's angle of view (a perspective sensor's, a projector's): fov along fov_axis,
// or Mitsuba 3's default from focal_length.
void load_fov(const XmlNode &node, Camera &cam);
// An IOR given as a number or a name from Mitsuba's table ("bk7", "air"...).
float ior_param(const XmlNode &node, const std::string &name, float def);

}  // namespace neepp::loader
