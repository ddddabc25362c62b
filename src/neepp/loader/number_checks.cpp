#include "neepp/loader/factories.h"

namespace neepp::loader {

// Each check names the property and its value as written, at the property's line. What is not finite the
// parser has refused already; these are the bounds of what a shape's or an emitter's numbers can mean.
void check_shape_numbers(const XmlNode &node) {
    const std::string &t = node.type;
    if (t == "sphere" || t == "cylinder") node.get_float("radius", 1.f, NumberRange::above(0));
    if (t == "serialized") node.get_int("shape_index", 0, NumberRange::at_least(0));
    for (const auto &child : node.children) {
        if (child->tag == "emitter") check_emitter_numbers(*child);
        // A shapegroup's shapes are built by the instances that use it.
        if (t == "shapegroup" && child->tag == "shape") check_shape_numbers(*child);
    }
}

void check_emitter_numbers(const XmlNode &node) {
    const std::string &t = node.type;
    // A negative scale is a negative emission: it would render a negative image (Mitsuba 3 does).
    if (t == "envmap" || t == "projector") node.get_float("scale", 1.f, NumberRange::at_least(0));
    if (t == "spot") {
        const float cutoff = node.get_float("cutoff_angle", 20.f, NumberRange{0, 180, true, false});
        node.get_float("beam_width", cutoff * 3.f / 4.f, NumberRange{0, cutoff, false, true});
    }
}

}  // namespace neepp::loader
