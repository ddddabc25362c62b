#include <set>
#include <vector>
#include <fmt/core.h>
#include "neepp/loader/supported_plugins.h"
#include "neepp/loader/factories.h"
#include "neepp/loader/plugins.h"
#include "neepp/loader/problems.h"
#include "neepp/textures/bitmap_texture.h"
#include "neepp/textures/checkerboard_texture.h"
#include "neepp/shapes/triangle_mesh.h"
#include "neepp/textures/mesh_attribute_texture.h"

namespace neepp::loader {

void warn_unused(const XmlNode &node) {
    for (const std::string &p : node.unused_properties())
        warn(node.file, node.line, fmt::format("<{} type=\"{}\"> ignores property '{}'", node.tag, node.type, p));
}

TexturePtr Factories::texture(const XmlNode &node) {
    if (auto it = textures_.find(&node); it != textures_.end()) return it->second;
    if (node.tag != "texture") throw node.error("expected a <texture>, found <" + node.tag + ">");
    TexturePtr tex;
    if (node.type == "bitmap") {
        BitmapOptions o;
        try {
            o.filter = parse_filter_type(node.get_string("filter_type", "bilinear"));
            o.wrap = parse_wrap_mode(node.get_string("wrap_mode", "repeat"));
        } catch (const std::exception &e) {
            throw node.error(e.what());
        }
        o.raw = node.get_bool("raw", false);
        o.to_uv = node.get_transform("to_uv");
        std::string path = node.resolve_path(node.get_string("filename"));
        try {
            tex = BitmapTexture::load(path, o);
        } catch (const std::exception &e) {  // missing or corrupt image: name the element that wants it
            throw node.error(e.what());
        }
    } else if (node.type == "checkerboard") {
        tex = std::make_shared<CheckerboardTexture>(texture_param(node, "color0", Color(0.4f)),
                                                    texture_param(node, "color1", Color(0.2f)),
                                                    node.get_transform("to_uv"));
    } else if (node.type == "mesh_attribute") {
        try {
            tex = std::make_shared<MeshAttributeTexture>(node.get_string("name"), node.get_float("scale", 1.f));
        } catch (const std::invalid_argument &e) {
            throw node.error(e.what());
        }
    } else if (node.type == "rawconstant") {
        // The value as written, neither colour-converted nor range-checked (a normal map's raw (0.5, 0.5, 1)):
        // a float is broadcast to three channels, a vector kept per channel.
        if (!node.has("value")) throw node.error("needs a 'value' (a float or a vector)");
        bool scalar = node.props.at("value").kind == XmlProperty::Kind::Float ||
                      node.props.at("value").kind == XmlProperty::Kind::Integer;
        tex = constant_texture(scalar ? Color(node.get_float("value")) : Color(node.get_vector("value")));
    } else if (const TexturePlugin *plugin = find_texture_plugin(node.type)) {
        tex = located_at(node, [&] { return (*plugin)(PluginProperties(node, *this)); });
        if (!tex) throw node.error("the '" + node.type + "' plugin built no texture");
    } else {
        throw node.error("unsupported texture type '" + node.type + "' (supported: " + supported_list("texture") + ")");
    }
    warn_unused(node);
    textures_[&node] = tex;
    return tex;
}

void check_mesh_attributes(const XmlNode &bsdf_node, const Shape &shape, const XmlNode &shape_node) {
    // Each object once: through <ref>s the objects under a BSDF are a graph, which a walk of every path
    // would take 2^depth steps over (a chain of textures that each use the previous one twice).
    std::set<const XmlNode *> seen;
    std::vector<const XmlNode *> stack{&bsdf_node};
    while (!stack.empty()) {
        const XmlNode *node = stack.back();
        stack.pop_back();
        for (const auto &child : node->children) {
            if (!seen.insert(child.get()).second) continue;
            if (child->tag == "texture" && child->type == "mesh_attribute") {
                const std::string name = child->get_string("name");
                const auto *mesh = dynamic_cast<const TriangleMesh *>(&shape);
                if (!mesh || !mesh->attribute(name)) {
                    std::string have;
                    if (mesh && mesh->attributes)
                        for (const MeshAttribute &a : *mesh->attributes) have += (have.empty() ? "" : ", ") + a.name;
                    throw shape_node.error("has no mesh attribute \"" + name + "\" (read by the mesh_attribute texture at " +
                                           child->file + ":" + std::to_string(child->line) + "); it has " +
                                           (have.empty() ? std::string("none") : have));
                }
            }
            stack.push_back(child.get());
        }
    }
}

TexturePtr Factories::texture_param_or_null(const XmlNode &node, const std::string &name, bool unbounded) {
    if (auto child = node.child(name)) return texture(*child);
    if (node.has(name)) return constant_texture(unbounded ? node.get_unbounded_rgb(name, Color(0.f)) : node.get_rgb(name));
    return nullptr;
}

TexturePtr Factories::texture_param(const XmlNode &node, const std::string &name, Color def, bool unbounded) {
    if (TexturePtr t = texture_param_or_null(node, name, unbounded)) return t;
    return constant_texture(def);
}

}  // namespace neepp::loader
