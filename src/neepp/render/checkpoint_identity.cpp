#include "neepp/render/checkpoint_identity.h"

#include <filesystem>
#include <stdexcept>
#include <fmt/format.h>
#include "neepp/io/atomic_file.h"
#include "neepp/visibility/map_file.h"

namespace neepp {

nlohmann::json render_identity(const Scene &scene, const Integrator &integrator, uint64_t seed,
                               const std::string &sampler, const std::map<std::string, std::string> &parameters) {
    return {{"scene", std::filesystem::absolute(scene.source_path).lexically_normal().string()},
            {"scene_fingerprint", fmt::format("{:016x}", scene_fingerprint(scene))},
            {"parameters", parameters},
            {"integrator", integrator.describe()},
            {"seed", seed},
            {"sampler", sampler},
            {"film", fmt::format("{}x{}", scene.camera.width, scene.camera.height)},
            {"crop", fmt::format("{},{} of {}x{}", scene.camera.crop_x, scene.camera.crop_y, scene.camera.film_width,
                                 scene.camera.film_height)},
            {"rfilter", fmt::format("{} {} {}", scene.settings.rfilter, scene.settings.rfilter_radius,
                                    scene.settings.rfilter_stddev)}};
}

namespace {

std::string distributed_words(const nlohmann::json &d) {
    return fmt::format("--ray --workers {}", d.value("workers", 0));
}

}  // namespace

RenderCheckpoint checkpoint_to_resume(const std::string &path, const nlohmann::json &identity) {
    if (!std::filesystem::exists(path))
        throw std::runtime_error(fmt::format("--resume: no checkpoint '{}' (a render with --checkpoint writes it)", path));
    RenderCheckpoint c = load_checkpoint(path);
    nlohmann::json theirs;
    try {
        theirs = nlohmann::json::parse(c.identity);
    } catch (const nlohmann::json::exception &) {
        throw std::runtime_error(fmt::format("checkpoint '{}': malformed", path));
    }
    const bool theirs_distributed = theirs.contains("distributed"), mine_distributed = identity.contains("distributed");
    if (theirs_distributed && !mine_distributed)
        throw std::runtime_error(fmt::format("--resume: the checkpoint '{}' is of a distributed render ({}), which only a "
                                             "distributed render continues: resume it with {}",
                                             path, distributed_words(theirs["distributed"]),
                                             distributed_words(theirs["distributed"])));
    if (mine_distributed && !theirs_distributed)
        throw std::runtime_error(fmt::format("--resume: the checkpoint '{}' is of a render on one machine, which only a "
                                             "render on one machine continues: resume it without --ray",
                                             path));
    for (const auto &[key, mine] : identity.items())
        if (!theirs.contains(key) || theirs[key] != mine) {
            const std::string was = theirs.contains(key) ? theirs[key].dump() : "missing";
            throw std::runtime_error(fmt::format("--resume: the checkpoint '{}' is of another render: its {} is {}, this "
                                                 "render's is {}", path, key, was, mine.dump()));
        }
    return c;
}

void remove_checkpoint(const std::string &path) {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    remove_stale_temporaries(path);
}

}  // namespace neepp
