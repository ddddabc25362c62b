// Mitsuba's `shapegroup` and `instance`, flattened: each instance adds copies of its group's shapes,
// moved by its to_world, to the scene. Embree could instance them without copies, but the rest of the
// renderer (hits, light sampling, NEE++'s voxels) knows world-space shapes only; the price is memory in
// proportion to the instances.
#include "neepp/loader/factories.h"
#include "neepp/loader/problems.h"

namespace neepp::loader {

const std::vector<std::unique_ptr<Shape>> &Factories::shape_group(const XmlNode &node) {
    if (auto it = shape_groups_.find(&node); it != shape_groups_.end()) return it->second;
    std::vector<std::unique_ptr<Shape>> shapes;
    for (const auto &child : node.children) attempt([&] {  // when checking, a broken member is left out
        // What Mitsuba's ShapeGroup refuses.
        if (child->tag != "shape") throw child->error("a shapegroup holds only shapes, not <" + child->tag + ">");
        if (child->type == "shapegroup") throw child->error("a shapegroup cannot hold another shapegroup");
        if (child->type == "instance") throw child->error("a shapegroup cannot hold an instance (no nested instancing)");
        const XmlNode *emitter_node = nullptr;
        std::unique_ptr<Shape> s = build_shape(*child, emitter_node);
        if (emitter_node) throw emitter_node->error("a shape in a shapegroup cannot carry an emitter (emitters are not instanced)");
        shapes.push_back(std::move(s));
    });
    warn_unused(node);
    return shape_groups_[&node] = std::move(shapes);
}

void Factories::instance(const XmlNode &node, Scene &scene) {
    const XmlNode *group = nullptr;
    for (const auto &child : node.children) {
        if (child->tag != "shape" || child->type != "shapegroup")
            throw node.error("an instance holds only a <ref> to a shapegroup, not <" + child->tag + " type=\"" +
                             child->type + "\">");
        if (group) throw node.error("an instance references a single shapegroup (it has a second)");
        group = child.get();
    }
    if (!group) throw node.error("an instance needs a <ref> to a shapegroup");
    const Transform to_world = node.get_transform("to_world");
    warn_unused(node);
    for (const auto &prototype : shape_group(*group)) {
        std::unique_ptr<Shape> s = prototype->clone();
        try {
            s->transform(to_world);
        } catch (const std::exception &e) {
            throw node.error(e.what());
        }
        scene.add_shape(std::move(s));
    }
}

}  // namespace neepp::loader
