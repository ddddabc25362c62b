// neepp.VisibilityMap: NEE++'s map with the grid it is keyed by, for scripts that build one, keep it in a
// file (the format a render's visibility_map option reads and writes) or look inside it.
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/unique_ptr.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include "bindings.h"
#include "neepp/scene/scene.h"
#include "neepp/visibility/map_file.h"
#include "neepp/visibility/map_seeding.h"

namespace neepp::python {

namespace {

struct GriddedMap {
    VoxelGrid grid;
    VisibilityMap map;
    uint64_t fingerprint = 0;
};

Vec3 point(const std::tuple<float, float, float> &p) { return {std::get<0>(p), std::get<1>(p), std::get<2>(p)}; }

void check_cell(const GriddedMap &m, uint32_t cell) {
    if (cell >= m.map.cell_count())
        throw nb::index_error(("cell " + std::to_string(cell) + " out of range (the map has " +
                               std::to_string(m.map.cell_count()) + " cells)").c_str());
}

}  // namespace

void bind_visibility(nb::module_ &m) {
    using Point = std::tuple<float, float, float>;
    nb::class_<GriddedMap>(m, "VisibilityMap",
                           "NEE++'s visibility map: for every pair of cells (voxels of an N^3 grid over the scene, then "
                           "96 direction bins standing for environment lights) the shadow rays traced between them and "
                           "how many were unoccluded.")
        .def_static("build", [](const Scene &scene, int resolution, int samples_per_pair, uint64_t seed) {
                auto m = std::make_unique<GriddedMap>();
                m->grid = VoxelGrid(scene.bounds(), resolution);
                m->map = VisibilityMap(m->grid.cell_count());
                m->fingerprint = scene_fingerprint(scene);
                SeedingOptions options;
                options.samples_per_pair = samples_per_pair;
                if (seed != 0) options.seed = seed;
                nb::gil_scoped_release release;
                seed_visibility_map(scene, m->grid, m->map, options);
                return m;
            },
            nb::arg("scene"), nb::arg("resolution") = 16, nb::arg("samples_per_pair") = 16, nb::arg("seed") = 0,
            "Seeds a map for the scene with explicit visibility samples, as a NEE++ render does before its first "
            "pass (seed 0: the renderer's own).")
        .def_static("load", [](const std::filesystem::path &path, const Scene &scene, std::optional<int> resolution) {
                // The file's grid: the scene's bounds, or a grid_bounds=shading render's (neepp view saves such
                // maps), which depend on the camera it rendered from and are known from the file alone.
                auto m = std::make_unique<GriddedMap>();
                m->fingerprint = scene_fingerprint(scene);
                auto [grid, map] = load_visibility_map(path.string(), m->fingerprint);
                if (resolution && *resolution != grid.resolution())
                    throw std::runtime_error("visibility map '" + path.string() + "': was built for a " +
                                             std::to_string(grid.resolution()) + "^3 grid, not " +
                                             std::to_string(*resolution) + "^3");
                m->grid = grid;
                m->map = std::move(map);
                return m;
            },
            nb::arg("path"), nb::arg("scene"), nb::arg("resolution").none() = nb::none(),
            "Reads a map file with the grid it was written for (its resolution and bounds: the scene's, or a "
            "grid_bounds=shading render's) and checks that it belongs to this scene (and, given one, to this grid "
            "resolution).")
        .def("save", [](const GriddedMap &m, const std::filesystem::path &path) { save_visibility_map(path.string(), m.grid, m.map, m.fingerprint); },
             nb::arg("path"), "Writes the map file (replaced atomically); a render's visibility_map option reads it.")
        .def_prop_ro("resolution", [](const GriddedMap &m) { return m.grid.resolution(); }, "N: the grid has N^3 voxels.")
        .def_prop_ro("bounds", [](const GriddedMap &m) {
                const BBox &b = m.grid.bounds();
                return nb::make_tuple(nb::make_tuple(b.lo.x, b.lo.y, b.lo.z), nb::make_tuple(b.hi.x, b.hi.y, b.hi.z));
            },
            "The grid's box (the scene's, enlarged by 1 % of its diagonal).")
        .def_prop_ro("voxel_count", [](const GriddedMap &m) { return m.grid.voxel_count(); })
        .def_prop_ro("cell_count", [](const GriddedMap &m) { return m.grid.cell_count(); },
                     "Voxels then direction bins: cells [voxel_count, cell_count) are directions.")
        .def_prop_ro("pair_count", [](const GriddedMap &m) { return m.map.pair_count(); })
        .def_prop_ro("known_pairs", [](const GriddedMap &m) { return m.map.known_pairs(); }, "Pairs with a traced ray.")
        .def("voxel_of", [](const GriddedMap &m, const Point &p) { return m.grid.voxel_of(point(p)); }, nb::arg("point"),
             "The voxel cell holding a point (clamped to the grid).")
        .def("direction_cell", [](const GriddedMap &m, const Point &d) { return m.grid.cell_of_direction(point(d)); },
             nb::arg("direction"), "The direction-bin cell of a direction (toward an environment light).")
        .def("pair_index", [](const GriddedMap &m, uint32_t a, uint32_t b) {
                check_cell(m, a);
                check_cell(m, b);
                return VisibilityMap::pair_index(a, b);
            },
            nb::arg("a"), nb::arg("b"), "The row of counts() that holds the (unordered) pair.")
        .def("estimate", [](const GriddedMap &m, uint32_t a, uint32_t b) {
                check_cell(m, a);
                check_cell(m, b);
                return m.map.estimate(a, b);
            },
            nb::arg("a"), nb::arg("b"),
            "Ṽ(a, b) = (visible + 1) / (traced + 2): the estimated probability that points of the two cells see "
            "each other (0.5 for a pair never traced; see known).")
        .def("known", [](const GriddedMap &m, uint32_t a, uint32_t b) {
                check_cell(m, a);
                check_cell(m, b);
                return m.map.known(a, b);
            },
            nb::arg("a"), nb::arg("b"))
        .def("visibility", [](const GriddedMap &m, const Point &p, const Point &q) {
                return m.map.estimate(m.grid.voxel_of(point(p)), m.grid.voxel_of(point(q)));
            },
            nb::arg("p"), nb::arg("q"), "Ṽ between the voxels of two points.")
        .def("add", [](GriddedMap &m, uint32_t a, uint32_t b, uint64_t visible, uint64_t traced) {
                check_cell(m, a);
                check_cell(m, b);
                if (visible > traced) throw std::invalid_argument("visible must not exceed traced");
                m.map.add(a, b, visible, traced);
            },
            nb::arg("a"), nb::arg("b"), nb::arg("visible"), nb::arg("traced"),
            "Adds outcomes to a pair (counts past 65535 are halved together, keeping their ratio).")
        .def("counts", [](GriddedMap &m) {
                auto *data = const_cast<PairCounts *>(m.map.data().data());
                return nb::ndarray<nb::numpy, uint16_t, nb::shape<-1, 2>>(reinterpret_cast<uint16_t *>(data),
                                                                           {size_t(m.map.pair_count()), 2}, nb::handle());
            },
            nb::rv_policy::reference_internal,
            "The counts of every pair as a (pair_count, 2) uint16 array (visible, traced), a view into the map: "
            "writes change it. Row pair_index(a, b) is the pair (a, b).");
}

}  // namespace neepp::python
