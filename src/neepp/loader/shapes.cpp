#include <cmath>
#include <fmt/core.h>
#include "neepp/loader/supported_plugins.h"
#include "neepp/io/curve_reader.h"
#include "neepp/io/obj_reader.h"
#include "neepp/io/ply_reader.h"
#include "neepp/io/serialized_reader.h"
#include "neepp/io/volume_grid_reader.h"
#include "neepp/lights/area_light.h"
#include "neepp/lights/environment_light.h"
#include "neepp/lights/directional_light.h"
#include "neepp/lights/projector_light.h"
#include "neepp/lights/spot_light.h"
#include "neepp/math/frame.h"
#include "neepp/loader/factories.h"
#include "neepp/loader/plugins.h"
#include "neepp/loader/problems.h"
#include "neepp/textures/bitmap_texture.h"
#include "neepp/shapes/curve_shape.h"
#include "neepp/shapes/sdf_grid_shape.h"
#include "neepp/shapes/sphere.h"
#include "neepp/shapes/triangle_mesh.h"

namespace neepp::loader {
namespace {

// Mitsuba's `rectangle`: [-1,1]^2 in the z = 0 plane, normal +z.
MeshData rectangle_mesh() {
    MeshData m;
    m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    m.normals.assign(4, Vec3(0, 0, 1));
    m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.indices = {0, 1, 2, 2, 3, 0};
    return m;
}

// Mitsuba's `cube`: [-1,1]^3, four vertices per face so each face has its own outward normal, with
// Mitsuba's face order and texture coordinates: a face is the point n + (2u - 1) U + (2v - 1) V of its
// uv square, its corners in the order uv (0,1), (1,1), (1,0), (0,0), triangles (0,1,2) and (3,0,2). The
// uv axes decide dp/du, so textures and anisotropic lobes land on a cube as they do in Mitsuba.
MeshData cube_mesh() {
    struct Face {
        Vec3 n, u, v;  // cross(u, v) = -n: the triangles wind counter-clockwise seen from outside
    };
    const Face faces[6] = {
        {{0, -1, 0}, {0, 0, 1}, {1, 0, 0}},  {{0, 1, 0}, {-1, 0, 0}, {0, 0, -1}},
        {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}},  {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}},
        {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}},  {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},
    };
    const Vec2 corners[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    MeshData m;
    for (const Face &f : faces) {
        const uint32_t base = uint32_t(m.positions.size());
        for (const Vec2 &uv : corners) {
            m.positions.push_back(f.n + f.u * (2 * uv.x - 1) + f.v * (2 * uv.y - 1));
            m.normals.push_back(f.n);
            m.uvs.push_back(uv);
        }
        m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base + 3, base, base + 2});
    }
    return m;
}

// Mitsuba's `disk` and `cylinder` are analytic; here they are meshes fine enough that the difference is
// below any render's noise (a 256-gon's area is 1 - 1e-4 of the circle's), with Mitsuba's normals and uvs,
// and hits on them take the analytic shape's uv, partials and shading normal (shapes/analytic_uv.h).
constexpr int kRoundSegments = 256;

// `disk`: the unit disk in the z = 0 plane, normal +z, uv = (r, φ / 2π). A fan whose triangles each have
// their own centre vertex, so that φ interpolates within each.
MeshData disk_mesh() {
    MeshData m;
    for (int i = 0; i <= kRoundSegments; ++i) {
        const float v = float(i) / kRoundSegments, phi = 2 * kPi * v;
        m.positions.push_back({std::cos(phi), std::sin(phi), 0});
        m.uvs.push_back({1.f, v});
    }
    for (int i = 0; i < kRoundSegments; ++i) {
        const uint32_t centre = uint32_t(m.positions.size());
        m.positions.push_back({0, 0, 0});
        m.uvs.push_back({0.f, (float(i) + 0.5f) / kRoundSegments});
        m.indices.insert(m.indices.end(), {centre, uint32_t(i), uint32_t(i + 1)});
    }
    m.normals.assign(m.positions.size(), Vec3(0, 0, 1));
    return m;
}

// `cylinder`: radius 1 about the z axis from z = 0 to 1, open at both ends, normals outward,
// uv = (φ / 2π, z).
MeshData cylinder_mesh() {
    MeshData m;
    for (int i = 0; i <= kRoundSegments; ++i) {
        const float u = float(i) / kRoundSegments, phi = 2 * kPi * u;
        const Vec3 radial(std::cos(phi), std::sin(phi), 0);
        for (float z : {0.f, 1.f}) {
            m.positions.push_back(radial + Vec3(0, 0, z));
            m.normals.push_back(radial);
            m.uvs.push_back({u, z});
        }
    }
    for (uint32_t i = 0; i < uint32_t(kRoundSegments); ++i) {
        const uint32_t b0 = 2 * i, t0 = b0 + 1, b1 = b0 + 2, t1 = b0 + 3;
        m.indices.insert(m.indices.end(), {b0, b1, t1, t1, t0, b0});
    }
    return m;
}

// Mitsuba's cylinder frame: p0 to p1, of the given radius, inside the shape's to_world.
Transform cylinder_frame(const XmlNode &node) {
    const Vec3 p0 = node.get_vector("p0", Vec3(0, 0, 0)), p1 = node.get_vector("p1", Vec3(0, 0, 1));
    const float radius = node.get_float("radius", 1.f, NumberRange::above(0)), length = norm(p1 - p0);
    if (!(radius > 0) || !std::isfinite(radius)) throw node.error("cylinder radius must be positive and finite");
    if (!(length > 0) || !std::isfinite(length)) throw node.error("cylinder p0 and p1 must be distinct finite points");
    const Frame f(normalize(p1 - p0));
    Matrix4 m = Matrix4::identity();
    for (int r = 0; r < 3; ++r) {
        m.m[r][0] = f.s[r] * radius;
        m.m[r][1] = f.t[r] * radius;
        m.m[r][2] = f.n[r] * length;
        m.m[r][3] = p0[r];
    }
    return Transform(m);
}

// Mitsuba's `sdfgrid`: the single-channel grid of a .vol file over [0, 1]^3 (the file's own bounds are not
// used, as in Mitsuba), with its `normals` option.
std::shared_ptr<const SdfGrid> load_sdf_grid(const XmlNode &node) {
    const std::string normals = node.get_string("normals", "smooth");
    if (normals != "smooth" && normals != "analytic")
        throw node.error("sdfgrid normals must be \"smooth\" or \"analytic\", not \"" + normals + "\"");
    // Mitsuba's other source, a `grid` tensor, can be given from Python or C++ only, never in XML.
    if (!node.has("filename")) throw node.error("an sdfgrid needs a 'filename': its grid as a .vol file");
    const std::string path = node.resolve_path(node.get_string("filename"));
    try {  // the file's own error, located at the shape using it
        VolumeGrid grid = read_volume_grid(path);
        if (!grid.warning.empty()) warn(node.file, node.line, path + ": " + grid.warning);
        if (grid.channels != 1)
            throw SceneError(path, "an sdfgrid's grid has " + std::to_string(grid.channels) + " channels, expected 1");
        try {
            return std::make_shared<const SdfGrid>(grid.size[0], grid.size[1], grid.size[2], std::move(grid.values),
                                                   normals == "smooth" ? SdfGrid::Normals::Smooth
                                                                       : SdfGrid::Normals::Analytic);
        } catch (const std::invalid_argument &e) {
            throw SceneError(path, e.what());
        }
    } catch (const std::exception &e) {
        throw node.error(e.what());
    }
}

// Smooth vertex normals for meshes that have none, weighting each face by its angle at the vertex
// (Mitsuba's recompute_vertex_normals).
void compute_vertex_normals(TriangleMesh &s) {
    s.normals.assign(s.positions.size(), Vec3(0.f));
    for (size_t t = 0; t < s.triangle_count(); ++t) {
        uint32_t idx[3] = {s.indices[3 * t], s.indices[3 * t + 1], s.indices[3 * t + 2]};
        Vec3 n = cross(s.positions[idx[1]] - s.positions[idx[0]], s.positions[idx[2]] - s.positions[idx[0]]);
        float len = norm(n);
        if (!(len > 0)) continue;
        n = n / len;
        for (int k = 0; k < 3; ++k) {
            Vec3 e1 = s.positions[idx[(k + 1) % 3]] - s.positions[idx[k]];
            Vec3 e2 = s.positions[idx[(k + 2) % 3]] - s.positions[idx[k]];
            float l1 = norm(e1), l2 = norm(e2);
            if (!(l1 > 0 && l2 > 0)) continue;
            float angle = std::acos(std::clamp(dot(e1, e2) / (l1 * l2), -1.f, 1.f));
            s.normals[idx[k]] += n * angle;
        }
    }
    for (Vec3 &n : s.normals) {
        float len = norm(n);
        n = len > 0 ? n / len : Vec3(0, 0, 1);
    }
}

// Mitsuba's `linearcurve` and `bsplinecurve`: the file's control points moved by to_world, their radii
// as written (Mitsuba's to_world does not scale them).
std::unique_ptr<CurveShape> make_curves(CurveBasis basis, CurveData curves, const Transform &to_world) {
    auto s = std::make_unique<CurveShape>();
    s->basis = basis;
    s->points.resize(curves.points.size());
    for (size_t i = 0; i < curves.points.size(); ++i) {
        s->points[i] = {to_world.point(curves.points[i]), curves.radii[i]};
        if (!is_finite(s->points[i].p)) throw std::runtime_error("the transformed curve has non-finite control points");
    }
    s->segments = std::move(curves.segments);
    return s;
}

std::unique_ptr<TriangleMesh> make_mesh(MeshData mesh, const Transform &to_world, bool face_normals,
                                        std::optional<AnalyticUv> analytic_uv = std::nullopt) {
    auto s = std::make_unique<TriangleMesh>();
    s->face_normals = face_normals;
    s->analytic_uv = analytic_uv;  // in the mesh's own space: transform() below takes it to the world
    s->positions = std::move(mesh.positions);
    s->normals = std::move(mesh.normals);
    s->uvs = std::move(mesh.uvs);
    s->indices = std::move(mesh.indices);
    if (!mesh.attributes.empty()) s->attributes = std::make_shared<const std::vector<MeshAttribute>>(std::move(mesh.attributes));
    s->transform(to_world);
    if (!s->face_normals && s->normals.empty()) compute_vertex_normals(*s);
    return s;
}

// A registered shape's mesh is checked as a mesh file's is: indices in range and by threes, one normal
// and one uv per position where there are any, finite positions.
void check_mesh(const MeshData &m, const XmlNode &node) {
    auto bad = [&](const std::string &what) { return node.error("the '" + node.type + "' plugin built a bad mesh: " + what); };
    if (m.indices.size() % 3 != 0) throw bad("its index count is not a multiple of 3");
    for (uint32_t i : m.indices)
        if (i >= m.positions.size()) throw bad("index " + std::to_string(i) + " is past its " + std::to_string(m.positions.size()) + " positions");
    if (!m.normals.empty() && m.normals.size() != m.positions.size()) throw bad("it has normals, but not one per position");
    if (!m.uvs.empty() && m.uvs.size() != m.positions.size()) throw bad("it has uvs, but not one per position");
    for (const Vec3 &p : m.positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) throw bad("a position is not finite");
}

// Whether the shape has a surface: a mesh with no triangles, or only degenerate ones (a scale of 0,
// collinear vertices), has none, and an emitter on it would be a light of zero area, which neither
// light sampling nor emission sampling can sample a point of.
bool has_surface(const Shape &shape) {
    const auto *s = dynamic_cast<const TriangleMesh *>(&shape);
    if (!s) return true;
    for (size_t t = 0; t + 2 < s->indices.size(); t += 3) {
        const Vec3 &a = s->positions[s->indices[t]];
        if (norm(cross(s->positions[s->indices[t + 1]] - a, s->positions[s->indices[t + 2]] - a)) > 0) return true;
    }
    return false;
}

}  // namespace

void Factories::shape(const XmlNode &node, Scene &scene) {
    if (node.type == "shapegroup") {  // built now so that its problems are found even with no instance
        shape_group(node);
        return;
    }
    if (node.type == "instance") {
        instance(node, scene);
        return;
    }
    const XmlNode *emitter_node = nullptr;
    std::unique_ptr<Shape> s = build_shape(node, emitter_node);
    Shape *shape = s.get();
    scene.add_shape(std::move(s));
    if (emitter_node) attempt([&] {
        if (dynamic_cast<const CurveShape *>(shape))  // Mitsuba loads it, then fails at the first render
            throw emitter_node->error("a " + node.type + " cannot carry an emitter (curves have no surface area "
                                      "to sample a point of; Mitsuba 3 cannot render one either)");
        if (emitter_node->type != "area") throw emitter_node->error("a shape can only carry an 'area' emitter");
        if (dynamic_cast<const SdfGridShape *>(shape))
            throw emitter_node->error("an sdfgrid cannot carry an area emitter (Mitsuba 3's sdfgrid cannot be an emitter)");
        TexturePtr radiance = texture_param(*emitter_node, "radiance", Color(1.f));
        warn_unused(*emitter_node);
        if (!has_surface(*shape)) {
            warn(node.file, node.line, "the " + node.type + " shape has no surface (no triangle of non-zero area): its "
                                       "area emitter is left out");
            return;
        }
        shape->area_light = scene.add_light(std::make_unique<AreaLight>(shape, radiance));
    });
}

std::unique_ptr<Shape> Factories::build_shape(const XmlNode &node, const XmlNode *&emitter_node) {
    const std::string &t = node.type;
    // Mitsuba's sdfgrid and curves have neither option: left unread, either is reported as unused.
    bool face_normals = false, flip_normals = false;
    if (t != "sdfgrid" && t != "linearcurve" && t != "bsplinecurve") {
        face_normals = node.get_bool("face_normals", false);
        flip_normals = node.get_bool("flip_normals", false);
    }
    Transform to_world = node.get_transform("to_world");
    std::unique_ptr<Shape> s;
    try {
        if (t == "obj" || t == "ply" || t == "serialized") {
            std::string path = node.resolve_path(node.get_string("filename"));
            const int shape_index = t == "serialized" ? node.get_int("shape_index", 0, NumberRange::at_least(0)) : 0;
            MeshData mesh;
            try {
                mesh = t == "obj" ? read_obj(path) : t == "ply" ? read_ply(path) : read_serialized(path, shape_index);
            } catch (const std::exception &e) {  // the mesh's own error, located at the shape using it
                throw node.error(e.what());
            }
            s = make_mesh(std::move(mesh), to_world, face_normals);
        } else if (t == "linearcurve" || t == "bsplinecurve") {
            const CurveBasis basis = t == "linearcurve" ? CurveBasis::Linear : CurveBasis::BSpline;
            const std::string path = node.resolve_path(node.get_string("filename"));
            CurveData curves;
            try {
                curves = read_curves(path, basis);
            } catch (const std::exception &e) {  // the file's own error, located at the shape using it
                throw node.error(e.what());
            }
            s = make_curves(basis, std::move(curves), to_world);
        } else if (t == "rectangle") {
            s = make_mesh(rectangle_mesh(), to_world, face_normals);
        } else if (t == "cube") {
            s = make_mesh(cube_mesh(), to_world, face_normals);
        } else if (t == "disk") {
            s = make_mesh(disk_mesh(), to_world, face_normals, AnalyticUv{AnalyticUv::Surface::Disk, {}});
        } else if (t == "cylinder") {
            s = make_mesh(cylinder_mesh(), to_world * cylinder_frame(node), face_normals,
                          AnalyticUv{AnalyticUv::Surface::Cylinder, {}});
        } else if (t == "sphere") {
            auto sphere = std::make_unique<Sphere>();
            sphere->center = node.get_vector("center", Vec3(0.f));
            sphere->radius = node.get_float("radius", 1.f, NumberRange::above(0));
            if (!(sphere->radius > 0) || !std::isfinite(sphere->radius)) throw node.error("sphere radius must be positive and finite");
            sphere->transform(to_world);
            s = std::move(sphere);
        } else if (t == "sdfgrid") {
            auto grid = std::make_unique<SdfGridShape>();
            grid->grid = load_sdf_grid(node);
            grid->transform(to_world);
            s = std::move(grid);
        } else if (const ShapePlugin *plugin = find_shape_plugin(t)) {
            MeshData mesh = (*plugin)(PluginProperties(node, *this));
            check_mesh(mesh, node);
            s = make_mesh(std::move(mesh), to_world, face_normals);
        } else {
            throw node.error("unsupported shape type '" + t + "' (supported: " + supported_list("shape") + ")");
        }
    } catch (const SceneError &) {
        throw;
    } catch (const std::exception &e) {
        throw node.error(e.what());
    }
    s->id = node.id;
    s->flip_normals = flip_normals;

    emitter_node = nullptr;
    for (size_t i = 0; i < node.children.size(); ++i) {
        const auto &child = node.children[i];
        attempt([&] {  // when checking, a broken BSDF leaves the shape the default one
            if (child->tag == "bsdf") {
                s->bsdf = bsdf(*child);
                check_mesh_attributes(*child, *s, node);
            } else if (child->tag == "emitter") {
                emitter_node = child.get();
            } else if (child->tag == "medium") {
                // Named where it is nested or <ref>'d: the shape bounds it from inside or from outside.
                const std::string &name = node.child_names[i];
                if (name != "interior" && name != "exterior")
                    throw child->error("a shape's medium is its \"interior\" or its \"exterior\" (name it so), not \"" +
                                       name + "\"");
                (name == "interior" ? s->interior : s->exterior) = medium(*child);
            } else {
                throw child->error("unsupported inside a shape: <" + child->tag + ">");
            }
        });
    }
    // Mitsuba's default: diffuse 0.5, black on an emitter (a light without a BSDF reflects nothing).
    if (!s->bsdf) s->bsdf = emitter_node ? black_bsdf() : default_bsdf();
    warn_unused(node);
    return s;
}

void Factories::emitter(const XmlNode &node, Scene &scene) {
    const std::string &t = node.type;
    if (t == "envmap") {
        std::string path = node.resolve_path(node.get_string("filename"));
        Image img;
        try {
            img = read_image(path);
        } catch (const std::exception &e) {
            throw node.error(e.what());
        }
        if (img.srgb_encoded)
            for (float &v : img.data) v = srgb_to_linear(v);
        // A negative scale is a negative emission: it would render a negative image (Mitsuba 3 does).
        float scale = node.get_float("scale", 1.f, NumberRange::at_least(0));
        scene.add_light(std::make_unique<EnvironmentMapLight>(std::move(img), node.get_transform("to_world"), scale));
    } else if (t == "constant") {
        scene.add_light(std::make_unique<ConstantEnvironmentLight>(node.get_rgb("radiance", Color(1.f))));
    } else if (t == "point") {
        Vec3 pos = node.get_vector("position", node.get_transform("to_world").point(Vec3(0.f)));
        scene.add_light(std::make_unique<PointLight>(pos, node.get_rgb("intensity", Color(1.f))));
    } else if (t == "directional") {
        if (node.has("direction") && node.has("to_world"))
            throw node.error("give a directional light 'direction' or 'to_world', not both");
        const Vec3 travel = node.has("direction") ? node.get_vector("direction")
                                                  : node.get_transform("to_world").vector(Vec3(0, 0, 1));
        try {
            scene.add_light(std::make_unique<DirectionalLight>(travel, node.get_rgb("irradiance", Color(1.f))));
        } catch (const std::invalid_argument &e) {
            throw node.error(e.what());
        }
    } else if (t == "spot") {
        const float cutoff = node.get_float("cutoff_angle", 20.f, NumberRange{0, 180, true, false});
        const float beam = node.get_float("beam_width", cutoff * 3.f / 4.f, NumberRange{0, cutoff, false, true});
        try {
            scene.add_light(std::make_unique<SpotLight>(node.get_transform("to_world"), node.get_rgb("intensity", Color(1.f)),
                                                        cutoff, beam, texture_param_or_null(node, "texture")));
        } catch (const std::invalid_argument &e) {
            throw node.error(e.what());
        }
    } else if (t == "projector") {
        // The texture's resolution sets the projection's aspect ratio, as Mitsuba's (1 x 1 unless a bitmap).
        TexturePtr irradiance = texture_param(node, "irradiance", Color(1.f));
        Camera frame;
        frame.to_world = node.get_transform("to_world");
        load_fov(node, frame);
        if (auto *bitmap = dynamic_cast<const BitmapTexture *>(irradiance.get())) {
            frame.width = bitmap->width();
            frame.height = bitmap->height();
        } else {
            frame.width = frame.height = 1;
        }
        try {
            scene.add_light(std::make_unique<ProjectorLight>(frame, irradiance, node.get_float("scale", 1.f, NumberRange::at_least(0))));
        } catch (const std::invalid_argument &e) {
            throw node.error(e.what());
        }
    } else if (t == "area") {
        throw node.error("an 'area' emitter must be nested inside a <shape>");
    } else if (const EmitterPlugin *plugin = find_emitter_plugin(t)) {
        LightPtr light = located_at(node, [&] { return (*plugin)(PluginProperties(node, *this)); });
        if (!light) throw node.error("the '" + t + "' plugin built no emitter");
        scene.add_light(std::move(light));
    } else {
        throw node.error("unsupported emitter type '" + t + "' (supported: " + supported_list("emitter") + ")");
    }
    warn_unused(node);
}

}  // namespace neepp::loader
