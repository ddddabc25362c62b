// Hand-written PLY reader (no PLY library is packaged). Header rules follow Mitsuba 3's
// src/shapes/ply.h; unlike Mitsuba it also accepts non-triangular faces and variable-length lists
// in skipped elements.
#include "neepp/io/ply_reader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <map>
#include <sstream>

namespace neepp {

namespace {

enum class PlyType { I8, U8, I16, U16, I32, U32, I64, U64, F32, F64 };

const std::map<std::string, PlyType> kTypeNames = {
    {"char", PlyType::I8},     {"uchar", PlyType::U8},    {"short", PlyType::I16},   {"ushort", PlyType::U16},
    {"int", PlyType::I32},     {"uint", PlyType::U32},    {"float", PlyType::F32},   {"double", PlyType::F64},
    {"int8", PlyType::I8},     {"uint8", PlyType::U8},    {"int16", PlyType::I16},   {"uint16", PlyType::U16},
    {"int32", PlyType::I32},   {"uint32", PlyType::U32},  {"long", PlyType::I64},    {"ulong", PlyType::U64},
    {"int64", PlyType::I64},   {"uint64", PlyType::U64},  {"float32", PlyType::F32}, {"float64", PlyType::F64}};

bool is_integer(PlyType t) { return t != PlyType::F32 && t != PlyType::F64; }

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::F32;  // the item type for a list
    bool list = false;
    PlyType count_type = PlyType::U8;
};

struct PlyElement {
    std::string name;
    size_t count = 0;
    std::vector<PlyProperty> props;

    int find(std::initializer_list<const char *> names) const {
        for (const char *n : names)
            for (size_t k = 0; k < props.size(); ++k)
                if (props[k].name == n) return int(k);
        return -1;
    }
};

enum class Format { Ascii, LittleEndian, BigEndian };

struct PlyHeader {
    Format format = Format::Ascii;
    std::vector<PlyElement> elements;
    size_t body_offset = 0;
};

PlyHeader parse_header(const std::string &data, const std::string &path) {
    PlyHeader h;
    bool seen_format = false;
    size_t pos = 0;
    if (data.rfind("ply", 0) != 0) throw SceneError(path, 1, "not a PLY file (it does not start with \"ply\")");
    for (int line = 1;; ++line) {
        size_t nl = data.find('\n', pos);
        if (nl == std::string::npos) throw SceneError(path, "truncated PLY header (no end_header)");
        std::istringstream in(data.substr(pos, nl - pos));
        pos = nl + 1;
        auto fail = [&](const std::string &problem) -> void { throw SceneError(path, line, "invalid PLY header: " + problem); };
        std::string token, extra;
        if (!(in >> token)) continue;
        if (token == "ply") {
            if (line != 1) fail("duplicate \"ply\"");
        } else if (token == "comment" || token == "obj_info") {
            continue;
        } else if (token == "format") {
            std::string fmt, version;
            in >> fmt >> version;
            if (fmt == "ascii") h.format = Format::Ascii;
            else if (fmt == "binary_little_endian") h.format = Format::LittleEndian;
            else if (fmt == "binary_big_endian") h.format = Format::BigEndian;
            else fail("unknown format \"" + fmt + "\"");
            if (version != "1.0") fail("unknown version \"" + version + "\"");
            seen_format = true;
        } else if (token == "element") {
            PlyElement el;
            if (!(in >> el.name >> el.count)) fail("\"element\" needs a name and a count");
            h.elements.push_back(el);
        } else if (token == "property") {
            if (h.elements.empty()) fail("\"property\" before any \"element\"");
            PlyProperty p;
            std::string type;
            in >> type;
            if (type == "list") {
                std::string count_type;
                in >> count_type >> type;
                auto c = kTypeNames.find(count_type);
                if (c == kTypeNames.end() || !is_integer(c->second)) fail("bad list count type \"" + count_type + "\"");
                p.list = true;
                p.count_type = c->second;
            }
            auto t = kTypeNames.find(type);
            if (t == kTypeNames.end()) fail("unknown property type \"" + type + "\"");
            p.type = t->second;
            if (!(in >> p.name)) fail("property without a name");
            h.elements.back().props.push_back(p);
        } else if (token == "end_header") {
            if (!seen_format) fail("no \"format\" line");
            // Every record takes at least one byte, so a larger count means a corrupt header (and
            // must not reach a huge allocation).
            for (const PlyElement &el : h.elements)
                if (!el.props.empty() && el.count > data.size() - pos)
                    fail("element \"" + el.name + "\" claims " + std::to_string(el.count) + " records, more than the file holds");
            h.body_offset = pos;
            return h;
        } else {
            fail("unknown keyword \"" + token + "\"");
        }
        if (in >> extra) fail("unexpected \"" + extra + "\" after \"" + token + "\"");
    }
}

// Binary body: values in the file's byte order.
class BinarySource {
public:
    BinarySource(const std::string &data, size_t offset, bool swap, const std::string &path)
        : p_(data.data() + offset), end_(data.data() + data.size()), swap_(swap), path_(path) {}

    double read(PlyType t) {
        switch (t) {
            case PlyType::I8: return get<int8_t>();
            case PlyType::U8: return get<uint8_t>();
            case PlyType::I16: return get<int16_t>();
            case PlyType::U16: return get<uint16_t>();
            case PlyType::I32: return get<int32_t>();
            case PlyType::U32: return get<uint32_t>();
            case PlyType::I64: return double(get<int64_t>());
            case PlyType::U64: return double(get<uint64_t>());
            case PlyType::F32: return get<float>();
            case PlyType::F64: return get<double>();
        }
        return 0;
    }
    bool at_end() const { return p_ == end_; }

private:
    const char *p_, *end_;
    bool swap_;
    const std::string &path_;

    template <class T>
    T get() {
        if (size_t(end_ - p_) < sizeof(T)) throw SceneError(path_, "truncated PLY file (data ends early)");
        std::array<char, sizeof(T)> bytes;
        std::memcpy(bytes.data(), p_, sizeof(T));
        p_ += sizeof(T);
        if (swap_) std::reverse(bytes.begin(), bytes.end());
        return std::bit_cast<T>(bytes);
    }
};

// ASCII body: whitespace-separated numbers.
class AsciiSource {
public:
    AsciiSource(const std::string &data, size_t offset, const std::string &path)
        : p_(data.data() + offset), end_(data.data() + data.size()), path_(path) {}

    double read(PlyType t) {
        skip_space();
        if (p_ == end_) throw SceneError(path_, "truncated PLY file (data ends early)");
        const char *start = p_;
        double v;
        bool ok = is_integer(t) ? parse_integer(v) : mesh_detail::parse_real(p_, end_, v);
        if (!ok || (p_ < end_ && !std::isspace((unsigned char)*p_)))
            throw SceneError(path_, "could not parse PLY value \"" + token_at(start) + "\"");
        return v;
    }
    bool at_end() {
        skip_space();
        return p_ == end_;
    }

private:
    const char *p_, *end_;
    const std::string &path_;

    void skip_space() {
        while (p_ < end_ && std::isspace((unsigned char)*p_)) ++p_;
    }
    bool parse_integer(double &v) {
        long long i;
        auto [q, ec] = std::from_chars(p_, end_, i);
        if (ec != std::errc() || q == p_) return false;
        p_ = q;
        v = double(i);
        return true;
    }
    std::string token_at(const char *s) const {
        const char *e = s;
        while (e < end_ && !std::isspace((unsigned char)*e)) ++e;
        return std::string(s, e);
    }
};

// An attribute as found in a PLY element: its name and the properties holding its components.
struct AttributeLayout {
    std::string name;
    std::vector<int> props;
};

// Mitsuba 3's grouping of the properties it does not read itself into attributes (src/shapes/ply.h):
// r, g, b (or red, green, blue), with a or alpha, make "<type>color"; other runs of consecutive
// properties named prefix_c, with c going x y z w, r g b a, 0 1 2 3 or 1 2 3 4, make "<type>prefix"
// ("<type>prefix_color" for r g b), kept with 1 or 3 components (4 for a colour with alpha). Anything
// else is skipped, as Mitsuba skips it (with a warning there).
std::vector<AttributeLayout> attribute_layouts(const PlyElement &el, const std::string &type,
                                               const std::vector<std::string> &reserved) {
    std::vector<AttributeLayout> out;
    auto is_reserved = [&](const PlyProperty &p) {
        return p.list || std::find(reserved.begin(), reserved.end(), p.name) != reserved.end();
    };
    for (auto names : {std::array<const char *, 4>{"r", "g", "b", "a"}, std::array<const char *, 4>{"red", "green", "blue", "alpha"}}) {
        const int r = el.find({names[0]}), g = el.find({names[1]}), b = el.find({names[2]});
        if (r < 0 || g < 0 || b < 0) continue;
        AttributeLayout color{type + "color", {r, g, b}};
        if (const int a = el.find({names[3]}); a >= 0) color.props.push_back(a);
        out.push_back(color);
        break;
    }
    const char *kPostfixes[4] = {"xr01", "yg12", "zb23", "wa34"};  // row: component; column: naming scheme
    std::vector<std::string> seen;
    AttributeLayout current;
    int scheme = -1;
    auto flush = [&] {
        if (scheme >= 0 && (current.props.size() == 1 || current.props.size() == 3)) {
            seen.push_back(current.name);
            current.name = type + current.name + (scheme == 1 ? "_color" : "");
            out.push_back(current);
        }
        current = {};
        scheme = -1;
    };
    for (size_t k = 0; k < el.props.size(); ++k) {
        const PlyProperty &p = el.props[k];
        if (is_reserved(p) || p.name == "r" || p.name == "g" || p.name == "b" || p.name == "a") continue;
        const size_t cut = p.name.find_last_of('_');
        if (cut == std::string::npos || cut + 2 != p.name.size()) {
            flush();
            continue;
        }
        const std::string prefix = p.name.substr(0, cut);
        const char c = p.name.back();
        if (scheme >= 0 && prefix != current.name) flush();
        if (scheme < 0) {
            if (std::find(seen.begin(), seen.end(), prefix) != seen.end()) continue;
            const char *at = std::strchr(kPostfixes[0], c);
            if (!at) continue;
            scheme = int(at - kPostfixes[0]);
            current = {prefix, {int(k)}};
        } else if (current.props.size() < 4 && kPostfixes[current.props.size()][scheme] == c) {
            current.props.push_back(int(k));
        } else {  // out of sequence: Mitsuba drops the attribute
            seen.push_back(current.name);
            current = {};
            scheme = -1;
        }
    }
    flush();
    return out;
}

template <class Source>
class BodyReader {
public:
    BodyReader(Source &src, const std::string &path) : src_(src), path_(path) {}

    MeshData read(const PlyHeader &h) {
        MeshData m;
        for (const PlyElement &el : h.elements) {
            if (el.name == "vertex") read_vertices(el, m);
            else if (el.name == "face") read_faces(el, m);
            else
                for (size_t r = 0; r < el.count; ++r) read_record(el, [](size_t, double) {}, nullptr);
        }
        if (!src_.at_end()) throw SceneError(path_, "unexpected data after the last PLY element");
        return m;
    }

private:
    Source &src_;
    const std::string &path_;
    std::vector<uint32_t> list_;

    // Reads one record; scalars go to on_scalar(property index, value), the items of the list
    // property `keep_list` (if any) into list_, and everything else is skipped.
    template <class OnScalar>
    void read_record(const PlyElement &el, OnScalar &&on_scalar, const PlyProperty *keep_list) {
        for (size_t k = 0; k < el.props.size(); ++k) {
            const PlyProperty &p = el.props[k];
            if (!p.list) {
                on_scalar(k, src_.read(p.type));
                continue;
            }
            double n = src_.read(p.count_type);
            if (n < 0) throw SceneError(path_, "negative list length in element \"" + el.name + "\"");
            if (&p == keep_list) list_.clear();
            for (size_t i = 0; i < size_t(n); ++i) {
                double v = src_.read(p.type);
                if (&p == keep_list) {
                    if (v < 0 || v > double(UINT32_MAX)) throw SceneError(path_, "invalid vertex index " + std::to_string(v));
                    list_.push_back(uint32_t(v));
                }
            }
        }
    }

    void read_vertices(const PlyElement &el, MeshData &m) {
        // Slots 0-2 position, 3-5 normal, 6-7 uv; each property maps to at most one slot.
        std::vector<int> slot(el.props.size(), -1);
        auto map = [&](int first_slot, std::initializer_list<std::initializer_list<const char *>> names) {
            std::vector<int> found;
            for (auto alternatives : names) found.push_back(el.find(alternatives));
            if (std::find(found.begin(), found.end(), -1) != found.end()) return false;
            for (size_t k = 0; k < found.size(); ++k) slot[found[k]] = first_slot + int(k);
            return true;
        };
        if (!map(0, {{"x"}, {"y"}, {"z"}})) throw SceneError(path_, "PLY vertex element lacks x, y or z");
        bool normals = map(3, {{"nx"}, {"ny"}, {"nz"}});
        // Mitsuba's accepted texture coordinate names, in its order of preference.
        bool uvs = map(6, {{"u"}, {"v"}}) || map(6, {{"texture_u"}, {"texture_v"}}) || map(6, {{"s"}, {"t"}});

        std::vector<std::string> reserved{"x", "y", "z", "nx", "ny", "nz"};
        for (int k = 0; k < int(slot.size()); ++k)
            if (slot[k] >= 6) reserved.push_back(el.props[k].name);
        const std::vector<AttributeLayout> layouts = attribute_layouts(el, "vertex_", reserved);
        Attributes attrs(layouts, el, m);

        m.positions.reserve(el.count + 1);  // a spare element: Embree shares the array (TriangleMesh::precompute)
        m.positions.resize(el.count);
        if (normals) m.normals.resize(el.count);
        if (uvs) m.uvs.resize(el.count);
        float values[8] = {};
        for (size_t r = 0; r < el.count; ++r) {
            read_record(el, [&](size_t k, double v) {
                if (slot[k] >= 0) values[slot[k]] = float(v);
                attrs.store(k, v);
            }, nullptr);
            m.positions[r] = Vec3(values[0], values[1], values[2]);
            if (normals) m.normals[r] = Vec3(values[3], values[4], values[5]);
            if (uvs) m.uvs[r] = Vec2(values[6], values[7]);
            attrs.next_record(1);
        }
    }

    // Gathers a record's attribute values (by property index) and appends them, once per vertex or once
    // per triangle a face became.
    class Attributes {
    public:
        Attributes(const std::vector<AttributeLayout> &layouts, const PlyElement &el, MeshData &m)
            : first_(m.attributes.size()), m_(m), where_(el.props.size(), {-1, -1}) {
            for (size_t a = 0; a < layouts.size(); ++a) {
                m.attributes.push_back({layouts[a].name, int(layouts[a].props.size()), {}});
                for (size_t c = 0; c < layouts[a].props.size(); ++c) where_[layouts[a].props[c]] = {int(a), int(c)};
            }
            record_.resize(layouts.size() * 4);
        }
        void store(size_t prop, double v) {
            if (where_[prop].first >= 0) record_[where_[prop].first * 4 + where_[prop].second] = float(v);
        }
        void next_record(size_t copies) {
            for (size_t a = first_; a < m_.attributes.size(); ++a) {
                MeshAttribute &attr = m_.attributes[a];
                for (size_t i = 0; i < copies; ++i)
                    attr.values.insert(attr.values.end(), record_.begin() + (a - first_) * 4,
                                       record_.begin() + (a - first_) * 4 + attr.dim);
            }
        }

    private:
        size_t first_;
        MeshData &m_;
        std::vector<std::pair<int, int>> where_;  // property -> (attribute, component)
        std::vector<float> record_;
    };

    void read_faces(const PlyElement &el, MeshData &m) {
        int list = el.find({"vertex_indices", "vertex_index"});
        if (list < 0 || !el.props[list].list)
            throw SceneError(path_, "PLY face element lacks a vertex_indices/vertex_index list");
        m.indices.reserve(m.indices.size() + el.count * 3);
        Attributes attrs(attribute_layouts(el, "face_", {}), el, m);
        for (size_t r = 0; r < el.count; ++r) {
            read_record(el, [&](size_t k, double v) { attrs.store(k, v); }, &el.props[list]);
            for (size_t k = 2; k < list_.size(); ++k) m.indices.insert(m.indices.end(), {list_[0], list_[k - 1], list_[k]});
            attrs.next_record(list_.size() >= 3 ? list_.size() - 2 : 0);  // each triangle of the face has its values
        }
    }
};

template <class Source>
MeshData read_body(Source src, const PlyHeader &h, const std::string &path) {
    return BodyReader<Source>(src, path).read(h);
}

}  // namespace

MeshData read_ply(const std::string &path) {
    std::string data = mesh_detail::read_file(path);
    PlyHeader h = parse_header(data, path);
    MeshData m;
    if (h.format == Format::Ascii) {
        m = read_body(AsciiSource(data, h.body_offset, path), h, path);
    } else {
        bool file_is_little = h.format == Format::LittleEndian;
        bool swap = file_is_little != (std::endian::native == std::endian::little);
        m = read_body(BinarySource(data, h.body_offset, swap, path), h, path);
    }
    mesh_detail::finish_mesh(m, path);
    return m;
}

}  // namespace neepp
