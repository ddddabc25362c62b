// Mitsuba 3 XML scene files parsed into a generic tree of nodes with typed properties. A separate
// factory turns the tree into renderer objects; this layer only knows the file format.
#pragma once
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>
#include "neepp/io/scene_error.h"
#include "neepp/math/spectrum.h"
#include "neepp/math/transform.h"

namespace neepp {

struct XmlProperty {
    // A <spectrum> is kept as one (Spectrum): the getters turn it into RGB, as Mitsuba's *_rgb variants
    // do, as a reflectance or, read by an emitter, as an emission.
    enum class Kind { Integer, Float, Boolean, String, RGB, Spectrum, Vector, Point, Transform };
    Kind kind = Kind::String;
    int64_t i = 0;
    double f = 0;
    bool b = false;
    std::string s;
    Vec3 v;  // RGB, Vector and Point
    Transform xf;
    Spectrum spectrum;
    std::string text;  // the value as written (after $ substitution), for messages
    int line = 0;
    mutable bool used = false;  // set by XmlNode's getters, so unread properties can be reported
};

const char *kind_name(XmlProperty::Kind kind);

// The values a numeric property can mean. A read outside them is an error naming the property and its value
// as written; a value that is not finite never gets that far (the parser refuses it).
struct NumberRange {
    double min = -HUGE_VAL, max = HUGE_VAL;
    bool min_open = false, max_open = false;
    static NumberRange at_least(double v) { return {v, HUGE_VAL, false, false}; }
    static NumberRange above(double v) { return {v, HUGE_VAL, true, false}; }
    static NumberRange between(double lo, double hi) { return {lo, hi, false, false}; }
    bool contains(double v) const {
        return (min_open ? v > min : v >= min) && (max_open ? v < max : v <= max);
    }
    std::string describe() const;  // "must be >= 0", "must be in (0, 1]"
};

// How a colour property is bounded beyond being finite.
enum class ColorRange {
    Reflectance,  // an RGB within [0, 1] (Mitsuba 3's rule), a float or a spectrum not negative
    NonNegative,  // an emission, an index of refraction, a roughness, an absorption
    Signed,       // an angle
};

struct XmlNode {
    std::string tag;   // shape, bsdf, texture, emitter, sensor, film, rfilter, sampler, integrator, medium, ...
    std::string type;  // the plugin name, e.g. "obj"; "scene" for the root <scene>
    std::string id;    // empty when the element has no id
    std::string name;  // the element's own name attribute, e.g. "reflectance" for a nested texture
    std::string file;  // the XML file the element was read from, for messages
    int line = 0;
    std::string base_dir;  // directory that relative `filename` values are resolved against
    // Folders the scene's <path value="..."/> elements add, searched first (the last added first), as
    // Mitsuba's file resolver does; shared by every node of a scene and complete once it is parsed.
    std::shared_ptr<const std::vector<std::string>> search_dirs;
    std::map<std::string, XmlProperty> props;
    // Nested objects in document order. A <ref> puts the referenced node itself here, so an object
    // used by many others is one shared node.
    std::vector<std::shared_ptr<XmlNode>> children;
    // The name each child was given where it was used: the element's name attribute, or the name
    // attribute of the <ref> that brought it in (empty when none). Parallel to `children`.
    std::vector<std::string> child_names;

    bool has(const std::string &prop) const { return props.count(prop) != 0; }

    // Getters with a default return it when the property is absent; the others throw when it is
    // absent. All throw a SceneError naming file:line and the property on a type mismatch.
    float get_float(const std::string &prop) const;
    float get_float(const std::string &prop, float def) const;  // an integer is accepted too
    float get_float(const std::string &prop, float def, const NumberRange &range) const;
    int get_int(const std::string &prop) const;
    int get_int(const std::string &prop, int def) const;
    int get_int(const std::string &prop, int def, const NumberRange &range) const;
    bool get_bool(const std::string &prop) const;
    bool get_bool(const std::string &prop, bool def) const;
    std::string get_string(const std::string &prop) const;
    std::string get_string(const std::string &prop, const std::string &def) const;
    // rgb, spectrum, or float (grey); a spectrum as a reflectance (within [0, 1]), or as an emission on
    // an <emitter>. Bounded as a reflectance (ColorRange::Reflectance), or on an <emitter> as an emission
    // (not negative).
    Color get_rgb(const std::string &prop) const;
    Color get_rgb(const std::string &prop, const Color &def) const;
    // The same for a property Mitsuba reads unbounded (a conductor's eta and k): a spectrum only kept >= 0,
    // and the value bounded by `range` only.
    Color get_unbounded_rgb(const std::string &prop, const Color &def, ColorRange range = ColorRange::NonNegative) const;
    Vec3 get_vector(const std::string &prop) const;  // <vector> or <point>
    Vec3 get_vector(const std::string &prop, const Vec3 &def) const;
    Transform get_transform(const std::string &prop, const Transform &def = Transform()) const;

    // The nested object given under `child_name` (e.g. texture "reflectance"); null when none.
    std::shared_ptr<XmlNode> child(const std::string &child_name) const;
    // Nested objects with the given tag (e.g. all "bsdf" children), in document order.
    std::vector<std::shared_ptr<XmlNode>> children_with_tag(const std::string &child_tag) const;

    // `path` made absolute against the scene file's directory (unchanged when already absolute).
    std::string resolve_path(const std::string &path) const;
    // Properties no getter has read yet, so the factory can warn about misspelt or unsupported ones.
    std::vector<std::string> unused_properties() const;
    // An error located at this element: "file:line: <tag type="..."> problem".
    SceneError error(const std::string &problem) const;
    // An error located at the property's own line: "file:line: <tag type="...">: property "p" = "value as
    // written": problem" (at the element's line, without the value, when the property is absent).
    SceneError property_error(const std::string &prop, const std::string &problem) const;

private:
    // Marks the property used; null when absent and not required.
    const XmlProperty *find(const std::string &prop, bool required) const;
};

// Parses a Mitsuba 3 scene file. `defines` are the -D name=value parameters; they take precedence
// over the file's <default> values. Throws SceneError (file:line: problem) on any error. A define that
// no attribute substitutes is refused as Mitsuba 3 refuses it; when `unused_defines` is given, such
// defines ("name=value") are put there instead, for the caller to judge.
std::shared_ptr<XmlNode> parse_mitsuba_xml(const std::string &path,
                                           const std::map<std::string, std::string> &defines = {},
                                           std::vector<std::string> *unused_defines = nullptr);
// The problem text for unused defines ("name=value" each).
std::string unused_parameters_problem(const std::vector<std::string> &unused);

}  // namespace neepp
