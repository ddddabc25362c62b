// A hand-written OBJ parser rather than tinyobjloader: tinyobjloader turns unparsable numbers such
// as "nan" or "1.0x" into 0 without telling, and Mitsuba 3's own parser (src/shapes/obj.cpp), whose
// results we must match, only understands v/vt/vn/f anyway.
#include "neepp/io/obj_reader.h"

#include <cstring>

namespace neepp {

namespace {

constexpr uint32_t kNone = UINT32_MAX;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

void skip_blanks(const char *&p, const char *end) {
    while (p < end && is_blank(*p)) ++p;
}

class ObjParser {
public:
    explicit ObjParser(const std::string &path) : path_(path) {}

    MeshData parse(const std::string &text) {
        const char *p = text.data(), *end = p + text.size();
        while (p < end) {
            const char *eol = static_cast<const char *>(std::memchr(p, '\n', size_t(end - p)));
            if (!eol) eol = end;
            ++line_;
            parse_line(p, eol);
            p = eol + 1;
        }
        return build();
    }

private:
    // One output vertex: the 0-based (position, uv, normal) indices it was made from, and the next
    // vertex sharing its position (a per-position chain, as in Mitsuba, to find duplicates).
    struct Vertex {
        uint32_t v, t, n, next;
    };

    std::string path_;
    int line_ = 0;
    std::vector<Vec3> v_, vn_;
    std::vector<Vec2> vt_;
    std::vector<Vertex> vertices_;
    std::vector<uint32_t> first_with_position_;
    std::vector<uint32_t> indices_, face_;

    [[noreturn]] void fail(const std::string &problem) const { throw SceneError(path_, line_, problem); }

    template <int N>
    void read_reals(const char *&p, const char *eol, float (&out)[N]) {
        for (float &x : out) {
            skip_blanks(p, eol);
            double d;
            if (!mesh_detail::parse_real(p, eol, d)) fail("could not parse number in \"" + std::string(p, eol) + "\"");
            x = float(d);
        }
    }

    void parse_line(const char *p, const char *eol) {
        skip_blanks(p, eol);
        if (eol - p < 2) return;
        if (p[0] == 'v' && is_blank(p[1])) {
            float x[3];
            p += 2;
            read_reals(p, eol, x);
            v_.emplace_back(x[0], x[1], x[2]);
            if (!is_finite(v_.back())) fail("invalid (NaN or infinite) vertex position");
        } else if (p[0] == 'v' && p[1] == 'n' && p + 2 < eol && is_blank(p[2])) {
            float x[3];
            p += 3;
            read_reals(p, eol, x);
            vn_.emplace_back(x[0], x[1], x[2]);
            if (!is_finite(vn_.back())) fail("invalid (NaN or infinite) vertex normal");
        } else if (p[0] == 'v' && p[1] == 't' && p + 2 < eol && is_blank(p[2])) {
            float x[2];
            p += 3;
            read_reals(p, eol, x);
            if (!std::isfinite(x[0]) || !std::isfinite(x[1])) fail("invalid (NaN or infinite) texture coordinate");
            vt_.emplace_back(x[0], 1.f - x[1]);  // Mitsuba's flip_tex_coords, on by default for OBJ
        } else if (p[0] == 'f' && is_blank(p[1])) {
            parse_face(p + 2, eol);
        }
    }

    // OBJ indices are 1-based; negative ones count back from the latest element (which Mitsuba
    // itself does not support). Returns kNone for an absent index.
    uint32_t index(const char *&p, const char *eol, size_t count, const char *what, bool check_range) {
        long long i = 0;
        auto [q, ec] = std::from_chars(p, eol, i);
        if (ec != std::errc() || q == p) fail(std::string("could not parse ") + what + " index in face");
        p = q;
        long long resolved = i > 0 ? i - 1 : (long long)count + i;
        if (i == 0 || resolved < 0 || (check_range && resolved >= (long long)count))
            fail("face references " + std::string(what) + " " + std::to_string(i) + ", but " + std::to_string(count) +
                 " are defined so far");
        return uint32_t(resolved);
    }

    void parse_face(const char *p, const char *eol) {
        face_.clear();
        for (skip_blanks(p, eol); p < eol; skip_blanks(p, eol)) {
            // Positions must precede the face (as in Mitsuba); uv and normal ranges are checked at
            // the end, where Mitsuba checks them.
            uint32_t v = index(p, eol, v_.size(), "vertex", true), t = kNone, n = kNone;
            if (p < eol && *p == '/') {
                ++p;
                if (p < eol && *p != '/') t = index(p, eol, vt_.size(), "texture coordinate", false);
                if (p < eol && *p == '/') {
                    ++p;
                    n = index(p, eol, vn_.size(), "normal", false);
                }
            }
            if (p < eol && !is_blank(*p)) fail("malformed face corner near \"" + std::string(p, eol) + "\"");
            face_.push_back(vertex_id(v, t, n));
        }
        for (size_t k = 2; k < face_.size(); ++k) indices_.insert(indices_.end(), {face_[0], face_[k - 1], face_[k]});
    }

    uint32_t vertex_id(uint32_t v, uint32_t t, uint32_t n) {
        if (first_with_position_.size() < v_.size()) first_with_position_.resize(v_.size(), kNone);
        for (uint32_t id = first_with_position_[v]; id != kNone; id = vertices_[id].next)
            if (vertices_[id].t == t && vertices_[id].n == n) return id;
        uint32_t id = uint32_t(vertices_.size());
        vertices_.push_back({v, t, n, first_with_position_[v]});
        first_with_position_[v] = id;
        return id;
    }

    MeshData build() {
        line_ = 0;  // errors from here on concern the whole file
        MeshData m;
        bool any_uv = false, any_normal = false;
        for (const Vertex &x : vertices_) {
            if (x.t != kNone && x.t >= vt_.size())
                fail("face references texture coordinate " + std::to_string(x.t + 1) + ", but only " +
                     std::to_string(vt_.size()) + " are defined");
            if (x.n != kNone && x.n >= vn_.size())
                fail("face references normal " + std::to_string(x.n + 1) + ", but only " + std::to_string(vn_.size()) +
                     " are defined");
            any_uv |= x.t != kNone;
            any_normal |= x.n != kNone;
        }
        m.positions.reserve(vertices_.size() + 1);  // a spare element: Embree shares the array (TriangleMesh::precompute)
        for (const Vertex &x : vertices_) {
            m.positions.push_back(v_[x.v]);
            // Corners without a uv or normal, in a mesh where others have one, get zeros.
            if (any_uv) m.uvs.push_back(x.t != kNone ? vt_[x.t] : Vec2());
            if (any_normal) m.normals.push_back(x.n != kNone ? vn_[x.n] : Vec3());
        }
        m.indices = std::move(indices_);
        mesh_detail::finish_mesh(m, path_);
        return m;
    }
};

}  // namespace

MeshData read_obj(const std::string &path) { return ObjParser(path).parse(mesh_detail::read_file(path)); }

}  // namespace neepp
