// Which render a checkpoint belongs to: what --resume checks before it continues one, so that a
// checkpoint is never continued by a render that would sum different samples into it.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <nlohmann/json.hpp>
#include "neepp/base/integrator.h"
#include "neepp/render/checkpoint.h"
#include "neepp/scene/scene.h"

namespace neepp {

// What a checkpoint must match to be resumed: the same scene (file and geometry), scene parameters (-D),
// integrator and its options, seed, sampler, film and filter. A distributed render adds "distributed":
// its worker count and budget, on which its rounds depend (neepp.distributed).
nlohmann::json render_identity(const Scene &scene, const Integrator &integrator, uint64_t seed,
                               const std::string &sampler, const std::map<std::string, std::string> &parameters);

// Reads the checkpoint a --resume continues and checks that it is this render's: throws
// std::runtime_error naming the file, and what differs, when it is missing, damaged or another render's.
// A checkpoint of a distributed render is continued only by a distributed render, and one of a single
// machine only by a single machine: they split the samples into passes differently, and what NEE++
// learns depends on that split, so neither would continue to the image the other gives.
RenderCheckpoint checkpoint_to_resume(const std::string &path, const nlohmann::json &identity);

// Removes a finished render's checkpoint, and what saves of it that were killed half-way left.
void remove_checkpoint(const std::string &path);

}  // namespace neepp
