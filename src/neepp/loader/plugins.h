// Plugins a program adds to the scene loader: BSDF, texture, emitter and shape types it does not know,
// each under its XML type name with a function that builds it from its element. docs/extending.md has a
// worked example of each. Register before loading a scene that uses one, not while another thread loads.
#pragma once
#include <functional>
#include <string>
#include <vector>
#include "neepp/base/bsdf.h"
#include "neepp/base/light.h"
#include "neepp/io/mesh_data.h"
#include "neepp/io/xml_tree.h"

namespace neepp {

namespace loader {
class Factories;
}

// What a builder reads: its element's properties (node.get_float, get_rgb, get_string, get_transform,
// ...: each read is marked, so that a misspelt one is reported as unused), its textures and nested BSDFs
// as the loader builds them, and an error located at the element.
class PluginProperties {
public:
    PluginProperties(const XmlNode &node, loader::Factories &factories) : node(node), factories_(factories) {}
    const XmlNode &node;
    // The parameter `name` as a texture: a nested <texture>, an rgb/float/spectrum constant, or def.
    TexturePtr texture(const std::string &name, Color def) const;
    // The element's nested <bsdf> elements, built (for a BSDF that wraps others).
    std::vector<BSDFPtr> nested_bsdfs() const;
    // "FILE:LINE: problem", for a value the plugin cannot accept.
    SceneError error(const std::string &problem) const { return node.error(problem); }

private:
    loader::Factories &factories_;
};

using BSDFPlugin = std::function<BSDFPtr(const PluginProperties &)>;
using TexturePlugin = std::function<TexturePtr(const PluginProperties &)>;
// An emitter of its own (as point and envmap are), not an area emitter, which is nested in a shape.
using EmitterPlugin = std::function<LightPtr(const PluginProperties &)>;
// A shape as a triangle mesh in its own space: the loader places it by to_world and gives it its BSDF and
// its area emitter, as it does for its own meshes (rectangle, cube, obj).
using ShapePlugin = std::function<MeshData(const PluginProperties &)>;

// Each throws std::invalid_argument when the loader already knows the type name.
void register_bsdf(const std::string &type, BSDFPlugin build);
void register_texture(const std::string &type, TexturePlugin build);
void register_emitter(const std::string &type, EmitterPlugin build);
void register_shape(const std::string &type, ShapePlugin build);

// For the loader: the builder registered for a type, or null.
const BSDFPlugin *find_bsdf_plugin(const std::string &type);
const TexturePlugin *find_texture_plugin(const std::string &type);
const EmitterPlugin *find_emitter_plugin(const std::string &type);
const ShapePlugin *find_shape_plugin(const std::string &type);
// The type names registered for a kind (bsdf, texture, emitter, shape), sorted.
std::vector<std::string> registered_plugins(const std::string &kind);

}  // namespace neepp
