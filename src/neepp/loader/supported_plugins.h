// The Mitsuba 3 plugins the loader reads, by kind: what `neepp list` prints and what the loader's
// "unsupported ... (supported: ...)" errors name.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace neepp {

// Kinds (shape, bsdf, texture, emitter, sensor, film, rfilter, sampler, integrator) with their plugin names.
const std::vector<std::pair<std::string, std::vector<std::string>>> &supported_plugins();
// The plugins of one kind; throws std::logic_error for an unknown kind.
const std::vector<std::string> &supported_names(const std::string &kind);
// "a, b, c": the plugins of one kind, for messages.
std::string supported_list(const std::string &kind);

}  // namespace neepp
