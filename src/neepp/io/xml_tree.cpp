// Mitsuba 3 XML reader. The rules follow Mitsuba 3.9's src/core/parser.cpp: attribute checks,
// $parameter substitution, <default>, transform composition, <ref>/<alias>/<include>.
#include "neepp/io/xml_tree.h"
#include "neepp/math/spectrum.h"

#include <algorithm>
#include <charconv>
#include <cfloat>
#include <climits>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>
#include <string_view>
#include <pugixml.hpp>
#include "neepp/math/frame.h"

namespace neepp {

namespace fs = std::filesystem;

const char *kind_name(XmlProperty::Kind kind) {
    switch (kind) {
        case XmlProperty::Kind::Integer: return "integer";
        case XmlProperty::Kind::Float: return "float";
        case XmlProperty::Kind::Boolean: return "boolean";
        case XmlProperty::Kind::String: return "string";
        case XmlProperty::Kind::RGB: return "rgb";
        case XmlProperty::Kind::Spectrum: return "spectrum";
        case XmlProperty::Kind::Vector: return "vector";
        case XmlProperty::Kind::Point: return "point";
        case XmlProperty::Kind::Transform: return "transform";
    }
    return "?";
}

namespace {

std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

}  // namespace

std::string NumberRange::describe() const {
    if (max == HUGE_VAL && min == 0) return min_open ? "must be positive (> 0)" : "must be non-negative (>= 0)";
    if (max == HUGE_VAL) return std::string(min_open ? "must be > " : "must be >= ") + number_text(min);
    if (min == -HUGE_VAL) return std::string(max_open ? "must be < " : "must be <= ") + number_text(max);
    return std::string("out of range: must be in ") + (min_open ? "(" : "[") + number_text(min) + ", " + number_text(max) +
           (max_open ? ")" : "]");
}

// ---------------------------------------------------------------------------------------------
// XmlNode accessors
// ---------------------------------------------------------------------------------------------

namespace {

using Kind = XmlProperty::Kind;

[[noreturn]] void wrong_kind(const XmlNode &node, const std::string &prop, const XmlProperty &p,
                             const char *expected) {
    throw SceneError(node.file, p.line, "property \"" + prop + "\" of <" + node.tag + " type=\"" + node.type +
                                            "\"> is " + kind_name(p.kind) + ", expected " + expected);
}

float as_float(const XmlNode &n, const std::string &prop, const XmlProperty &p) {
    if (p.kind == Kind::Float) return float(p.f);
    if (p.kind == Kind::Integer) return float(p.i);
    wrong_kind(n, prop, p, "float");
}

int as_int(const XmlNode &n, const std::string &prop, const XmlProperty &p) {
    if (p.kind != Kind::Integer) wrong_kind(n, prop, p, "integer");
    if (p.i < INT_MIN || p.i > INT_MAX)
        throw n.property_error(prop, "out of the range of an integer here (" + std::to_string(INT_MIN) + " to " +
                                         std::to_string(INT_MAX) + ")");
    return int(p.i);
}

bool as_bool(const XmlNode &n, const std::string &prop, const XmlProperty &p) {
    if (p.kind != Kind::Boolean) wrong_kind(n, prop, p, "boolean");
    return p.b;
}

std::string as_string(const XmlNode &n, const std::string &prop, const XmlProperty &p) {
    if (p.kind != Kind::String) wrong_kind(n, prop, p, "string");
    return p.s;
}

// The bounds of a colour beyond being finite. Mitsuba 3 refuses an RGB reflectance outside [0, 1] (its
// srgb texture) and reads floats and spectra unchecked; a negative one means nothing anywhere (a negative
// emission renders a negative image), so it is refused too.
void check_color(const XmlNode &n, const std::string &prop, const XmlProperty &p, ColorRange range) {
    if (range == ColorRange::Signed) return;
    const char *what = n.tag == "emitter" ? "an emission cannot be negative" : "it cannot be negative";
    if (p.kind == Kind::Spectrum) {
        for (double v : p.spectrum.values)
            if (v < 0) throw n.property_error(prop, std::string("a spectrum with a negative value: ") + what);
        return;
    }
    const Color c = p.kind == Kind::RGB ? Color(p.v) : Color(float(p.f));
    if (c.x < 0 || c.y < 0 || c.z < 0) throw n.property_error(prop, std::string("negative: ") + what);
    if (range == ColorRange::Reflectance && p.kind == Kind::RGB && (c.x > 1 || c.y > 1 || c.z > 1))
        throw n.property_error(prop, "an RGB reflectance must be within [0, 1] (as in Mitsuba 3)");
}

// Mitsuba accepts a plain float wherever a spectrum is expected and treats it as a grey constant. A
// <spectrum> becomes RGB as Mitsuba's RGB variants make it: as emission when an emitter reads it.
Color as_rgb(const XmlNode &n, const std::string &prop, const XmlProperty &p, bool unbounded = false,
             ColorRange range = ColorRange::Reflectance) {
    if (p.kind != Kind::RGB && p.kind != Kind::Float && p.kind != Kind::Spectrum)
        wrong_kind(n, prop, p, "rgb, spectrum or float");
    check_color(n, prop, p, n.tag == "emitter" && range == ColorRange::Reflectance ? ColorRange::NonNegative : range);
    if (p.kind == Kind::RGB) return p.v;
    if (p.kind == Kind::Float) return Color(float(p.f));
    return spectrum_to_rgb(p.spectrum, n.tag == "emitter" ? SpectrumUse::Emission
                                       : unbounded        ? SpectrumUse::Unbounded
                                                          : SpectrumUse::Reflectance);
}

Vec3 as_vector(const XmlNode &n, const std::string &prop, const XmlProperty &p) {
    if (p.kind != Kind::Vector && p.kind != Kind::Point) wrong_kind(n, prop, p, "vector or point");
    return p.v;
}

}  // namespace

const XmlProperty *XmlNode::find(const std::string &prop, bool required) const {
    auto it = props.find(prop);
    if (it == props.end()) {
        if (required) throw error("missing required property \"" + prop + "\"");
        return nullptr;
    }
    it->second.used = true;
    return &it->second;
}

SceneError XmlNode::error(const std::string &problem) const {
    return SceneError(file, line, "<" + tag + (type.empty() ? "" : " type=\"" + type + "\"") + ">: " + problem);
}

SceneError XmlNode::property_error(const std::string &prop, const std::string &problem) const {
    const std::string element = "<" + tag + (type.empty() ? "" : " type=\"" + type + "\"") + ">: property \"" + prop + "\"";
    auto it = props.find(prop);
    if (it == props.end()) return SceneError(file, line, element + ": " + problem);
    return SceneError(file, it->second.line, element + " = \"" + it->second.text + "\": " + problem);
}

float XmlNode::get_float(const std::string &prop) const { return as_float(*this, prop, *find(prop, true)); }
float XmlNode::get_float(const std::string &prop, float def) const {
    const XmlProperty *p = find(prop, false);
    return p ? as_float(*this, prop, *p) : def;
}
float XmlNode::get_float(const std::string &prop, float def, const NumberRange &range) const {
    const float v = get_float(prop, def);
    if (has(prop) && !range.contains(v)) throw property_error(prop, range.describe());
    return v;
}
int XmlNode::get_int(const std::string &prop) const { return as_int(*this, prop, *find(prop, true)); }
int XmlNode::get_int(const std::string &prop, int def, const NumberRange &range) const {
    const int v = get_int(prop, def);
    if (has(prop) && !range.contains(v)) throw property_error(prop, range.describe());
    return v;
}
int XmlNode::get_int(const std::string &prop, int def) const {
    const XmlProperty *p = find(prop, false);
    return p ? as_int(*this, prop, *p) : def;
}
bool XmlNode::get_bool(const std::string &prop) const { return as_bool(*this, prop, *find(prop, true)); }
bool XmlNode::get_bool(const std::string &prop, bool def) const {
    const XmlProperty *p = find(prop, false);
    return p ? as_bool(*this, prop, *p) : def;
}
std::string XmlNode::get_string(const std::string &prop) const { return as_string(*this, prop, *find(prop, true)); }
std::string XmlNode::get_string(const std::string &prop, const std::string &def) const {
    const XmlProperty *p = find(prop, false);
    return p ? as_string(*this, prop, *p) : def;
}
Color XmlNode::get_rgb(const std::string &prop) const { return as_rgb(*this, prop, *find(prop, true)); }
Color XmlNode::get_rgb(const std::string &prop, const Color &def) const {
    const XmlProperty *p = find(prop, false);
    return p ? as_rgb(*this, prop, *p) : def;
}
Color XmlNode::get_unbounded_rgb(const std::string &prop, const Color &def, ColorRange range) const {
    const XmlProperty *p = find(prop, false);
    return p ? as_rgb(*this, prop, *p, true, range == ColorRange::Reflectance ? ColorRange::NonNegative : range) : def;
}
Vec3 XmlNode::get_vector(const std::string &prop) const { return as_vector(*this, prop, *find(prop, true)); }
Vec3 XmlNode::get_vector(const std::string &prop, const Vec3 &def) const {
    const XmlProperty *p = find(prop, false);
    return p ? as_vector(*this, prop, *p) : def;
}
Transform XmlNode::get_transform(const std::string &prop, const Transform &def) const {
    const XmlProperty *p = find(prop, false);
    if (!p) return def;
    if (p->kind != Kind::Transform) wrong_kind(*this, prop, *p, "transform");
    return p->xf;
}

std::shared_ptr<XmlNode> XmlNode::child(const std::string &child_name) const {
    for (size_t k = 0; k < children.size(); ++k)
        if (child_names[k] == child_name) return children[k];
    return nullptr;
}

std::vector<std::shared_ptr<XmlNode>> XmlNode::children_with_tag(const std::string &child_tag) const {
    std::vector<std::shared_ptr<XmlNode>> out;
    for (const auto &c : children)
        if (c->tag == child_tag) out.push_back(c);
    return out;
}

std::string XmlNode::resolve_path(const std::string &path) const {
    fs::path p(path);
    if (p.is_absolute()) return path;
    if (search_dirs)
        for (auto it = search_dirs->rbegin(); it != search_dirs->rend(); ++it) {
            std::error_code ec;
            const fs::path candidate = (fs::path(*it) / p).lexically_normal();
            if (fs::exists(candidate, ec)) return candidate.string();
        }
    if (base_dir.empty()) return path;
    return (fs::path(base_dir) / p).lexically_normal().string();
}

std::vector<std::string> XmlNode::unused_properties() const {
    std::vector<std::string> out;
    for (const auto &[key, p] : props)
        if (!p.used) out.push_back(key);
    return out;
}

// ---------------------------------------------------------------------------------------------
// Parser
// ---------------------------------------------------------------------------------------------

namespace {

// Mitsuba's tokenizer splits numeric lists at whitespace and commas alike.
std::vector<std::string_view> tokenize(std::string_view s) {
    std::vector<std::string_view> out;
    size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && (std::isspace((unsigned char)s[i]) || s[i] == ',')) ++i;
        size_t j = i;
        while (j < s.size() && !std::isspace((unsigned char)s[j]) && s[j] != ',') ++j;
        if (j > i) out.push_back(s.substr(i, j - i));
        i = j;
    }
    return out;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace((unsigned char)s.front())) s.remove_prefix(1);
    while (!s.empty() && std::isspace((unsigned char)s.back())) s.remove_suffix(1);
    return s;
}

// The whole (trimmed) string must be the number: "1.5x" is an error rather than 1.5.
bool parse_number(std::string_view s, double &out) {
    s = trim(s);
    if (s.size() > 1 && s[0] == '+' && s[1] != '-') s.remove_prefix(1);  // from_chars rejects '+'
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && end == s.data() + s.size() && !s.empty();
}

bool parse_integer(std::string_view s, int64_t &out) {
    s = trim(s);
    if (s.size() > 1 && s[0] == '+' && s[1] != '-') s.remove_prefix(1);
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && end == s.data() + s.size() && !s.empty();
}

bool iequals(std::string_view a, std::string_view b) {
    return a.size() == b.size() &&
           std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return std::tolower(x) == std::tolower(y); });
}

const std::set<std::string_view> kObjectTags = {"shape",   "bsdf",       "texture", "emitter", "sensor", "film",
                                                "rfilter", "sampler",    "integrator", "medium", "phase", "volume"};
const std::set<std::string_view> kTransformOps = {"translate", "rotate", "scale", "lookat", "matrix"};
constexpr int kMaxIncludeDepth = 15;  // Mitsuba's default; also stops include cycles
// Objects nested in objects, in the file or through <ref>s: no scene needs nearly as many, and the loader
// descends them recursively (parsing, resolving references, building), so a file must not choose how deep.
constexpr int kMaxObjectDepth = 100;
const char *kRefTag = "\x01ref";      // placeholder tag of an unresolved <ref>, never a real element name

// One XML file in memory, with the byte offset of each line start for file:line messages.
struct SourceFile {
    std::string path, dir;
    pugi::xml_document doc;
    std::vector<size_t> line_starts{0};

    int line_of(ptrdiff_t offset) const {
        return int(std::upper_bound(line_starts.begin(), line_starts.end(), size_t(std::max<ptrdiff_t>(offset, 0))) -
                   line_starts.begin());
    }
    int line_of(pugi::xml_node n) const { return line_of(n.offset_debug()); }
};

class Parser {
public:
    Parser(const std::map<std::string, std::string> &defines, std::string base_dir) : base_dir_(std::move(base_dir)) {
        for (const auto &[k, v] : defines) add_param(k, v, false);
    }

    // The -D parameters no attribute substituted, as "name=value".
    std::vector<std::string> unused_defines() const {
        std::vector<std::string> out;
        for (const Param &p : params_)
            if (!p.used) out.push_back(p.key.substr(1) + "=" + p.value);
        std::sort(out.begin(), out.end());
        return out;
    }

    std::shared_ptr<XmlNode> parse(const std::string &path) {
        std::shared_ptr<XmlNode> root = parse_file(path, 0);
        try {
            resolve_refs(*root);
            check_nesting(*root);
        } catch (...) {
            // A <ref> cycle is a cycle of shared_ptrs, which would outlive the error: every cycle passes
            // through an object with an id (what a <ref> points to), so unlinking their children frees it.
            for (auto &[id, node] : ids_) node->children.clear();
            throw;
        }
        return root;
    }

private:
    struct Param {
        std::string key, value;  // key includes the '$'
        bool used = true;        // a -D parameter starts unused; a <default> never counts as one
    };

    std::vector<Param> params_;  // longest key first, so "$resx2" is not substituted as "$resx" + "2"
    std::map<std::string, std::shared_ptr<XmlNode>> ids_;
    std::string base_dir_;
    std::shared_ptr<std::vector<std::string>> search_dirs_ = std::make_shared<std::vector<std::string>>();
    std::vector<std::string> includer_dirs_;  // folders of the files whose <include> is being read, outermost first
    int object_depth_ = 0;                    // make_object calls under way

    void add_param(const std::string &name, const std::string &value, bool from_default) {
        Param p{"$" + name, value, from_default};
        auto pos = std::find_if(params_.begin(), params_.end(), [&](const Param &q) { return p.key.size() > q.key.size(); });
        params_.insert(pos, std::move(p));
    }
    bool has_param(const std::string &name) const {
        return std::any_of(params_.begin(), params_.end(), [&](const Param &p) { return p.key == "$" + name; });
    }

    [[noreturn]] static void fail(const SourceFile &src, pugi::xml_node n, const std::string &problem) {
        throw SceneError(src.path, src.line_of(n), problem);
    }

    std::shared_ptr<XmlNode> parse_file(const std::string &path, int depth) {
        SourceFile src;
        src.path = path;
        src.dir = fs::path(path).parent_path().string();
        std::ifstream in(path, std::ios::binary);
        if (!in) throw SceneError(path, "cannot open scene file");
        std::stringstream ss;
        ss << in.rdbuf();
        std::string text = ss.str();
        for (size_t k = 0; k < text.size(); ++k)
            if (text[k] == '\n') src.line_starts.push_back(k + 1);

        pugi::xml_parse_result result = src.doc.load_buffer(text.data(), text.size());
        if (!result) throw SceneError(path, src.line_of(result.offset), std::string("malformed XML: ") + result.description());

        pugi::xml_node root_el;
        for (pugi::xml_node n : src.doc.children()) {
            if (n.type() != pugi::node_element) continue;
            if (root_el) fail(src, n, "more than one root element");
            root_el = n;
        }
        if (!root_el) throw SceneError(path, "no root element");
        return parse_root(src, root_el, depth);
    }

    std::shared_ptr<XmlNode> parse_root(const SourceFile &src, pugi::xml_node el, int depth) {
        substitute(src, el);
        std::string_view tag = el.name();
        if (tag != "scene" && !kObjectTags.count(tag)) fail(src, el, "root element <" + std::string(tag) + "> is not a scene or object");
        check_attributes(src, el, {"!version", "type", "id", "name"});
        std::string version = el.attribute("version").value();
        int64_t major = 0;
        size_t dot = version.find('.');
        if (!parse_integer(std::string_view(version).substr(0, dot), major))
            fail(src, el, "invalid version number \"" + version + "\"");
        // Mitsuba renames 0.x/1.x properties (camelCase) when loading such files; we do not.
        if (major < 2) fail(src, el, "scene version " + version + " is not supported: convert it to Mitsuba 3 (version 3.0.0)");
        if (tag != "scene" && !el.attribute("type")) fail(src, el, "missing required attribute \"type\" in <" + std::string(tag) + ">");
        return make_object(src, el, depth);
    }

    // Mitsuba substitutes $name in every attribute of every element, longest parameter name first;
    // "\$" escapes a literal dollar sign.
    void substitute(const SourceFile &src, pugi::xml_node el) {
        for (pugi::xml_attribute attr : el.attributes()) {
            std::string value = attr.value();
            if (value.find('$') == std::string::npos) continue;
            for (Param &p : params_) {
                for (size_t pos = value.find(p.key); pos != std::string::npos; pos = value.find(p.key, pos)) {
                    if (pos > 0 && value[pos - 1] == '\\') {
                        pos += p.key.size();
                        continue;
                    }
                    value.replace(pos, p.key.size(), p.value);
                    p.used = true;
                    pos += p.value.size();
                }
            }
            for (size_t pos = value.find('$'); pos != std::string::npos; pos = value.find('$', pos + 1)) {
                if (pos > 0 && value[pos - 1] == '\\') continue;
                size_t end = pos + 1;
                while (end < value.size() && (std::isalnum((unsigned char)value[end]) || value[end] == '_')) ++end;
                fail(src, el, "undefined parameter $" + value.substr(pos + 1, end - pos - 1) + " in attribute \"" +
                                  attr.name() + "\" (give it a <default> or define it with -D)");
            }
            for (size_t pos = value.find("\\$"); pos != std::string::npos; pos = value.find("\\$", pos + 1))
                value.erase(pos, 1);
            attr.set_value(value.c_str());
        }
    }

    // Unknown attributes are errors, as in Mitsuba: a typo must not be silently ignored.
    // Names starting with '!' are required.
    static void check_attributes(const SourceFile &src, pugi::xml_node el, std::initializer_list<std::string_view> allowed) {
        for (pugi::xml_attribute attr : el.attributes()) {
            bool ok = std::any_of(allowed.begin(), allowed.end(), [&](std::string_view a) {
                return (a[0] == '!' ? a.substr(1) : a) == attr.name();
            });
            if (!ok) fail(src, el, "unexpected attribute \"" + std::string(attr.name()) + "\" in <" + el.name() + ">");
        }
        for (std::string_view a : allowed)
            if (a[0] == '!' && !el.attribute(std::string(a.substr(1)).c_str()))
                fail(src, el, "missing required attribute \"" + std::string(a.substr(1)) + "\" in <" + el.name() + ">");
    }

    std::shared_ptr<XmlNode> make_object(const SourceFile &src, pugi::xml_node el, int depth) {
        struct Nesting {
            int &level;
            ~Nesting() { --level; }
        } nesting{++object_depth_};
        if (object_depth_ > kMaxObjectDepth)
            fail(src, el, "objects nested more than " + std::to_string(kMaxObjectDepth) + " deep (no scene needs so many)");
        auto node = std::make_shared<XmlNode>();
        // Mitsuba treats <spectrum type="..."> as a texture plugin.
        node->tag = std::string_view(el.name()) == "spectrum" ? "texture" : el.name();
        node->type = el.attribute("type") ? el.attribute("type").value() : "scene";
        node->id = el.attribute("id").value();
        node->name = el.attribute("name").value();
        node->file = src.path;
        node->line = src.line_of(el);
        node->base_dir = base_dir_;
        node->search_dirs = search_dirs_;
        if (!node->id.empty()) {
            auto [it, inserted] = ids_.emplace(node->id, node);
            if (!inserted)
                fail(src, el, "duplicate id \"" + node->id + "\" (first declared at " + it->second->file + ":" +
                                  std::to_string(it->second->line) + ")");
        }
        for (pugi::xml_node c : el.children())
            if (c.type() == pugi::node_element) parse_element(src, c, *node, depth);
        return node;
    }

    static void claim_name(const SourceFile &src, pugi::xml_node el, const XmlNode &parent, const std::string &name) {
        if (name.empty()) return;
        if (parent.props.count(name) || std::count(parent.child_names.begin(), parent.child_names.end(), name))
            fail(src, el, "\"" + name + "\" is specified more than once in <" + parent.tag + ">");
    }

    void add_child(const SourceFile &src, pugi::xml_node el, XmlNode &parent, std::shared_ptr<XmlNode> child,
                   const std::string &name) {
        claim_name(src, el, parent, name);
        parent.children.push_back(std::move(child));
        parent.child_names.push_back(name);
    }

    void set_prop(const SourceFile &src, pugi::xml_node el, XmlNode &parent, XmlProperty p) {
        std::string name = el.attribute("name").value();
        claim_name(src, el, parent, name);
        p.line = src.line_of(el);
        if (p.text.empty()) p.text = el.attribute("value") ? el.attribute("value").value() : el.attribute("filename").value();
        parent.props.emplace(name, std::move(p));
    }

    // Every number in a scene becomes a 32-bit float: one that is not finite (nan, inf), or that overflows a
    // float (1e39), would render garbage or nothing without a word, so it is refused here, naming the
    // property (the element's, or for a step of a <transform> the transform's) and the value.
    double number(const SourceFile &src, pugi::xml_node el, std::string_view text, const char *what) {
        double v;
        if (!parse_number(text, v))
            fail(src, el, "could not parse " + std::string(what) + " value \"" + std::string(text) + "\" in <" + el.name() + ">");
        if (!std::isfinite(v) || std::abs(v) > FLT_MAX) {
            pugi::xml_attribute name = el.attribute("name");
            if (!name) name = el.parent().attribute("name");
            const std::string where = name ? "property \"" + std::string(name.value()) + "\": " : std::string();
            fail(src, el, where + "<" + el.name() + "> value \"" + std::string(trim(text)) + "\" " +
                              (std::isfinite(v) ? "overflows a 32-bit float (largest " + number_text(FLT_MAX) + ")"
                                                : std::string("is not a finite number")));
        }
        return v;
    }

    Vec3 three_numbers(const SourceFile &src, pugi::xml_node el, const char *attr) {
        auto tokens = tokenize(el.attribute(attr).value());
        if (tokens.size() != 3)
            fail(src, el, "attribute \"" + std::string(attr) + "\" of <" + el.name() + "> needs 3 values, got " +
                              std::to_string(tokens.size()));
        return Vec3(float(number(src, el, tokens[0], "floating point")), float(number(src, el, tokens[1], "floating point")),
                    float(number(src, el, tokens[2], "floating point")));
    }

    // value="v" or value="x y z", or separate x/y/z attributes (missing ones take `def`).
    Vec3 xyz(const SourceFile &src, pugi::xml_node el, float def, bool require_all) {
        pugi::xml_attribute value = el.attribute("value");
        if (value) {
            if (el.attribute("x") || el.attribute("y") || el.attribute("z"))
                fail(src, el, "<" + std::string(el.name()) + "> cannot mix \"value\" with \"x\"/\"y\"/\"z\"");
            auto tokens = tokenize(value.value());
            if (tokens.size() == 1) return Vec3(float(number(src, el, tokens[0], "floating point")));
            if (tokens.size() != 3)
                fail(src, el, "\"value\" of <" + std::string(el.name()) + "> must have 1 or 3 elements, got " +
                                  std::to_string(tokens.size()));
            return three_numbers(src, el, "value");
        }
        Vec3 v(def);
        const char *names[3] = {"x", "y", "z"};
        for (int k = 0; k < 3; ++k) {
            pugi::xml_attribute a = el.attribute(names[k]);
            if (a) v[k] = float(number(src, el, a.value(), "floating point"));
            else if (require_all)
                fail(src, el, "missing required attribute \"" + std::string(names[k]) + "\" in <" + el.name() + ">");
        }
        return v;
    }

    static void reject_children(const SourceFile &src, pugi::xml_node el) {
        for (pugi::xml_node c : el.children())
            if (c.type() == pugi::node_element)
                fail(src, c, "<" + std::string(c.name()) + "> cannot be nested in the property <" + el.name() + ">");
    }

    void parse_element(const SourceFile &src, pugi::xml_node el, XmlNode &parent, int depth) {
        substitute(src, el);
        std::string_view tag = el.name();
        XmlProperty p;

        if (kObjectTags.count(tag) || (tag == "spectrum" && el.attribute("type"))) {
            check_attributes(src, el, {"!type", "id", "name"});
            add_child(src, el, parent, make_object(src, el, depth), el.attribute("name").value());
            return;
        }
        if (tag == "transform") {
            check_attributes(src, el, {"!name"});
            p.kind = Kind::Transform;
            for (pugi::xml_node op : el.children())
                if (op.type() == pugi::node_element) p.xf = transform_op(src, op) * p.xf;
            // Each step is finite; their product can still overflow (two scales by 1e30).
            for (const auto &row : p.xf.matrix.m)
                for (float v : row)
                    if (!std::isfinite(v))
                        fail(src, el, "property \"" + std::string(el.attribute("name").value()) +
                                          "\": the <transform>'s steps compose to a matrix that is not finite");
            set_prop(src, el, parent, std::move(p));
            return;
        }
        reject_children(src, el);
        if (tag == "integer") {
            check_attributes(src, el, {"!name", "!value"});
            p.kind = Kind::Integer;
            if (!parse_integer(el.attribute("value").value(), p.i))
                fail(src, el, "property \"" + std::string(el.attribute("name").value()) +
                                  "\": could not parse integer value \"" + std::string(el.attribute("value").value()) +
                                  "\" (a whole number that fits 64 bits)");
        } else if (tag == "float") {
            check_attributes(src, el, {"!name", "!value"});
            p.kind = Kind::Float;
            p.f = number(src, el, el.attribute("value").value(), "floating point");
        } else if (tag == "boolean") {
            check_attributes(src, el, {"!name", "!value"});
            p.kind = Kind::Boolean;
            std::string_view v = trim(el.attribute("value").value());
            if (!iequals(v, "true") && !iequals(v, "false"))
                fail(src, el, "could not parse boolean value \"" + std::string(v) + "\": must be \"true\" or \"false\"");
            p.b = iequals(v, "true");
        } else if (tag == "string") {
            check_attributes(src, el, {"!name", "!value"});
            p.s = el.attribute("value").value();
        } else if (tag == "rgb") {
            check_attributes(src, el, {"!name", "!value"});
            p.kind = Kind::RGB;
            auto tokens = tokenize(el.attribute("value").value());
            if (tokens.size() == 1) p.v = Vec3(float(number(src, el, tokens[0], "RGB")));
            else if (tokens.size() == 3) p.v = three_numbers(src, el, "value");
            else fail(src, el, "<rgb> needs one or three values, got " + std::to_string(tokens.size()));
        } else if (tag == "spectrum") {
            // Kept as a spectrum: whether it is a reflectance or an emission decides its RGB.
            check_attributes(src, el, {"!name", "value", "filename"});
            p.kind = Kind::Spectrum;
            const pugi::xml_attribute value = el.attribute("value"), file = el.attribute("filename");
            if (bool(value) == bool(file)) fail(src, el, "<spectrum> needs either \"value\" or \"filename\" (not both)");
            try {
                p.spectrum = value ? parse_spectrum(value.value()) : read_spectrum_file(parent.resolve_path(file.value()));
            } catch (const std::exception &e) {
                fail(src, el, "property \"" + std::string(el.attribute("name").value()) + "\": <spectrum>: " + e.what());
            }
            for (double v : p.spectrum.values)
                if (!(std::abs(v) <= FLT_MAX))
                    fail(src, el, "property \"" + std::string(el.attribute("name").value()) + "\": <spectrum> value \"" +
                                      std::string(value ? value.value() : file.value()) + "\" holds " + number_text(v) +
                                      ", which overflows a 32-bit float (largest " + number_text(FLT_MAX) + ")");
        } else if (tag == "vector" || tag == "point") {
            check_attributes(src, el, {"!name", "value", "x", "y", "z"});
            p.kind = tag == "vector" ? Kind::Vector : Kind::Point;
            p.v = xyz(src, el, 0.f, true);
        } else if (tag == "ref") {
            check_attributes(src, el, {"!id", "name"});
            // Resolved once the whole file is read: Mitsuba resolves references by id after parsing.
            auto placeholder = std::make_shared<XmlNode>();
            placeholder->tag = kRefTag;
            placeholder->id = el.attribute("id").value();
            placeholder->file = src.path;
            placeholder->line = src.line_of(el);
            add_child(src, el, parent, placeholder, el.attribute("name").value());
            return;
        } else if (tag == "default") {
            check_attributes(src, el, {"!name", "!value"});
            std::string name = el.attribute("name").value();
            if (name.empty()) fail(src, el, "<default> needs a non-empty name");
            if (!has_param(name)) add_param(name, el.attribute("value").value(), true);
            return;
        } else if (tag == "alias") {
            check_attributes(src, el, {"!id", "!as"});
            std::string from = el.attribute("id").value(), to = el.attribute("as").value();
            auto it = ids_.find(from);
            if (it == ids_.end()) fail(src, el, "<alias>: unknown id \"" + from + "\"");
            if (!ids_.emplace(to, it->second).second) fail(src, el, "<alias>: id \"" + to + "\" already exists");
            return;
        } else if (tag == "path") {
            // A folder to look for files in, relative to the file that names it.
            check_attributes(src, el, {"!value"});
            reject_children(src, el);
            fs::path dir(el.attribute("value").value());
            if (dir.empty()) fail(src, el, "<path> needs a non-empty value");
            if (!dir.is_absolute()) dir = fs::path(src.dir) / dir;
            search_dirs_->push_back(fs::absolute(dir).lexically_normal().string());
            return;
        } else if (tag == "include") {
            check_attributes(src, el, {"!filename", "name"});
            include(src, el, parent, depth);
            return;
        } else if (kTransformOps.count(tag)) {
            fail(src, el, "<" + std::string(tag) + "> can only appear inside a <transform>");
        } else {
            fail(src, el, "unknown element <" + std::string(tag) + ">");
        }
        set_prop(src, el, parent, std::move(p));
    }

    // One step of a <transform>; the caller applies it after (to the left of) the steps before it.
    Transform transform_op(const SourceFile &src, pugi::xml_node op) {
        substitute(src, op);
        reject_children(src, op);
        std::string_view tag = op.name();
        if (tag == "translate") {
            check_attributes(src, op, {"value", "x", "y", "z"});
            return Transform::translate(xyz(src, op, 0.f, false));
        }
        if (tag == "scale") {
            check_attributes(src, op, {"value", "x", "y", "z"});
            return Transform::scale(xyz(src, op, 1.f, false));
        }
        if (tag == "rotate") {
            check_attributes(src, op, {"!angle", "value", "x", "y", "z"});
            Vec3 axis = xyz(src, op, 0.f, false);
            if (axis == Vec3(0.f)) fail(src, op, "<rotate> axis cannot be zero");
            return Transform::rotate(axis, float(number(src, op, op.attribute("angle").value(), "angle")));
        }
        if (tag == "lookat") {
            check_attributes(src, op, {"!origin", "!target", "up"});
            Vec3 origin = three_numbers(src, op, "origin"), target = three_numbers(src, op, "target");
            Vec3 up = op.attribute("up") ? three_numbers(src, op, "up") : Vec3(0.f);
            // Mitsuba picks an arbitrary perpendicular up vector when none is given.
            if (up == Vec3(0.f) && !(origin == target)) up = Frame(normalize(target - origin)).s;
            try {
                if (origin == target) throw std::runtime_error("origin equals target");
                return Transform::look_at(origin, target, up);
            } catch (const std::exception &e) {
                fail(src, op, std::string("invalid <lookat>: ") + e.what());
            }
        }
        if (tag == "matrix") {
            check_attributes(src, op, {"!value"});
            auto tokens = tokenize(op.attribute("value").value());
            if (tokens.size() != 16 && tokens.size() != 9)
                fail(src, op, "<matrix> needs 9 or 16 values, got " + std::to_string(tokens.size()));
            int n = tokens.size() == 16 ? 4 : 3;
            Matrix4 m = Matrix4::identity();
            for (int r = 0; r < n; ++r)
                for (int c = 0; c < n; ++c) m.m[r][c] = float(number(src, op, tokens[r * n + c], "matrix"));
            try {
                return Transform(m);
            } catch (const std::exception &e) {
                fail(src, op, std::string("<matrix> is not invertible: ") + e.what());
            }
        }
        fail(src, op, "unexpected <" + std::string(tag) + "> inside <transform>");
    }

    // Where Mitsuba's file resolver finds an included file: beside the including file, then beside each
    // file that (transitively) included it, innermost first (each <include> puts its file's folder in
    // front of the resolver for what it reads), then the <path> folders and the scene's folder. The
    // first candidate is the one a missing file is reported as.
    fs::path include_path(const SourceFile &src, const fs::path &name) const {
        if (name.is_absolute()) return name;
        std::vector<fs::path> dirs{src.dir};
        dirs.insert(dirs.end(), includer_dirs_.rbegin(), includer_dirs_.rend());
        dirs.insert(dirs.end(), search_dirs_->rbegin(), search_dirs_->rend());
        dirs.push_back(base_dir_);
        for (const fs::path &d : dirs) {
            std::error_code ec;
            if (fs::exists(d / name, ec)) return (d / name).lexically_normal();
        }
        return (fs::path(src.dir) / name).lexically_normal();
    }

    void include(const SourceFile &src, pugi::xml_node el, XmlNode &parent, int depth) {
        if (depth + 1 >= kMaxIncludeDepth) fail(src, el, "<include> nested too deeply (is a file including itself?)");
        fs::path file = include_path(src, el.attribute("filename").value());
        if (!fs::exists(file)) fail(src, el, "included file \"" + file.string() + "\" not found");
        includer_dirs_.push_back(src.dir);
        std::shared_ptr<XmlNode> root;
        try {
            root = parse_file(file.string(), depth + 1);
        } catch (...) {
            includer_dirs_.pop_back();
            throw;
        }
        includer_dirs_.pop_back();
        if (root->tag != "scene") {
            add_child(src, el, parent, root, el.attribute("name").value());
            return;
        }
        // An included <scene> contributes its objects; like Mitsuba, its plain properties are dropped.
        for (size_t k = 0; k < root->children.size(); ++k)
            add_child(src, el, parent, root->children[k], root->child_names[k]);
    }

    // Replaces each <ref> by the object it names. Iterative, as the walk below: through <ref>s, how deep
    // the objects go is the file's choice.
    void resolve_refs(XmlNode &root) {
        std::set<const XmlNode *> seen;
        std::vector<XmlNode *> stack{&root};
        while (!stack.empty()) {
            XmlNode *node = stack.back();
            stack.pop_back();
            if (!seen.insert(node).second) continue;
            for (auto &c : node->children) {
                if (c->tag == kRefTag) {
                    auto it = ids_.find(c->id);
                    if (it == ids_.end()) throw SceneError(c->file, c->line, "<ref>: unknown id \"" + c->id + "\"");
                    c = it->second;
                }
                stack.push_back(c.get());
            }
        }
    }

    // A <ref> to an enclosing object would make the factory recurse forever, and a chain of <ref>s as deep
    // as the file likes would exhaust its stack: a walk with a stack of its own finds the first and
    // measures the second (each object's height: the longest chain of objects below it).
    void check_nesting(const XmlNode &root) {
        std::map<const XmlNode *, int> height;  // of the objects walked; -1 while under way
        std::vector<std::pair<const XmlNode *, size_t>> stack{{&root, 0}};
        height[&root] = -1;
        while (!stack.empty()) {
            auto &[node, next] = stack.back();
            if (next < node->children.size()) {
                const XmlNode *c = node->children[next++].get();
                auto [it, fresh] = height.emplace(c, -1);
                if (fresh) stack.push_back({c, 0});
                else if (it->second < 0) throw c->error("object \"" + c->id + "\" contains itself through a <ref>");
                continue;
            }
            int h = 1;
            for (const auto &c : node->children) h = std::max(h, height.at(c.get()) + 1);
            if (h > kMaxObjectDepth)
                throw node->error("objects nested, through <ref>s, more than " + std::to_string(kMaxObjectDepth) +
                                  " deep (no scene needs so many)");
            height[node] = h;
            stack.pop_back();
        }
    }
};

}  // namespace

std::shared_ptr<XmlNode> parse_mitsuba_xml(const std::string &path, const std::map<std::string, std::string> &defines,
                                           std::vector<std::string> *unused_defines) {
    // Like Mitsuba's file resolver, relative file names resolve against the top-level scene's folder
    // (also for objects from included files).
    std::string dir = fs::absolute(fs::path(path)).parent_path().lexically_normal().string();
    Parser parser(defines, dir);
    std::shared_ptr<XmlNode> root = parser.parse(path);
    std::vector<std::string> unused = parser.unused_defines();
    if (unused_defines) *unused_defines = std::move(unused);
    else if (!unused.empty()) throw SceneError(path, unused_parameters_problem(unused));
    return root;
}

std::string unused_parameters_problem(const std::vector<std::string> &unused) {
    std::string list;
    for (const std::string &u : unused) list += (list.empty() ? "-D " : ", -D ") + u;
    return std::string("unused parameter") + (unused.size() == 1 ? "" : "s") + " " + list +
           ": the scene substitutes no such $name (a misspelt -D would otherwise be ignored; Mitsuba 3 refuses "
           "it too)";
}

}  // namespace neepp
