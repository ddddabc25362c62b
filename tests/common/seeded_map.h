// Renders of one scene that start from one seeded NEE++ visibility map: seeding it (a camera pre-pass and
// shadow rays between the cells, into a map of some 35 MB) can cost a small test render many times over.
#pragma once
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include "neepp/base/options.h"
#include "neepp/integrators/factory.h"

namespace neepp::testing {

// The options, and where the integrator keeps a visibility map, the file it reads the map from (or seeds it
// into, and saves it to, the first time): visibility_map = map_file. A map is seeded from the scene and the
// grid alone (not from the render's seed, nor from the integrator's other options), so every render of a
// scene may start from the map its first render seeded; each test that does has been checked, case by case
// and seed by seed, to render the same images with the file as without it, to the bit. Integrators without
// a map refuse the option as unused, and options that name a map file already keep theirs: those come back
// as they were.
inline std::map<std::string, std::string> with_map_file(const std::map<std::string, std::string> &options,
                                                        const std::string &map_file,
                                                        const std::string &integrator = "path") {
    if (options.count("visibility_map")) return options;
    std::map<std::string, std::string> with = options;
    with["visibility_map"] = map_file;
    try {
        make_integrator(integrator, Options(with));
    } catch (const std::invalid_argument &) {
        return options;
    }
    return with;
}

// A map file beside a scene file.
inline std::string map_file_beside(const std::string &scene_path, const std::string &name = "seeded.map") {
    return (std::filesystem::path(scene_path).parent_path() / name).string();
}

}  // namespace neepp::testing
