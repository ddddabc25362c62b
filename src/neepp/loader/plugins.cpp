#include "neepp/loader/plugins.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <stdexcept>
#include "neepp/loader/factories.h"
#include "neepp/loader/supported_plugins.h"

namespace neepp {

namespace {

// One kind's builders by type name.
template <typename Build> struct Registry {
    std::mutex mutex;
    std::map<std::string, Build> builders;  // a map: a registered builder's address never changes
};

template <typename Build> Registry<Build> &registry() {
    static Registry<Build> r;
    return r;
}

template <typename Build> void add(const char *kind, const std::string &type, Build build) {
    const std::vector<std::string> &own = supported_names(kind);
    if (type.empty() || std::find(own.begin(), own.end(), type) != own.end())
        throw std::invalid_argument(std::string("register: the loader has its own ") + kind + " '" + type + "'");
    Registry<Build> &r = registry<Build>();
    std::lock_guard<std::mutex> lock(r.mutex);
    r.builders[type] = std::move(build);
}

template <typename Build> const Build *find(const std::string &type) {
    Registry<Build> &r = registry<Build>();
    std::lock_guard<std::mutex> lock(r.mutex);
    auto it = r.builders.find(type);
    return it == r.builders.end() ? nullptr : &it->second;
}

template <typename Build> std::vector<std::string> names() {
    Registry<Build> &r = registry<Build>();
    std::lock_guard<std::mutex> lock(r.mutex);
    std::vector<std::string> out;
    for (const auto &[name, build] : r.builders) out.push_back(name);
    return out;
}

}  // namespace

TexturePtr PluginProperties::texture(const std::string &name, Color def) const {
    return factories_.texture_param(node, name, def);
}

std::vector<BSDFPtr> PluginProperties::nested_bsdfs() const {
    std::vector<BSDFPtr> out;
    for (const auto &child : node.children_with_tag("bsdf")) out.push_back(factories_.bsdf(*child));
    return out;
}

void register_bsdf(const std::string &type, BSDFPlugin build) { add("bsdf", type, std::move(build)); }
void register_texture(const std::string &type, TexturePlugin build) { add("texture", type, std::move(build)); }
void register_emitter(const std::string &type, EmitterPlugin build) { add("emitter", type, std::move(build)); }
void register_shape(const std::string &type, ShapePlugin build) { add("shape", type, std::move(build)); }

const BSDFPlugin *find_bsdf_plugin(const std::string &type) { return find<BSDFPlugin>(type); }
const TexturePlugin *find_texture_plugin(const std::string &type) { return find<TexturePlugin>(type); }
const EmitterPlugin *find_emitter_plugin(const std::string &type) { return find<EmitterPlugin>(type); }
const ShapePlugin *find_shape_plugin(const std::string &type) { return find<ShapePlugin>(type); }

std::vector<std::string> registered_plugins(const std::string &kind) {
    if (kind == "bsdf") return names<BSDFPlugin>();
    if (kind == "texture") return names<TexturePlugin>();
    if (kind == "emitter") return names<EmitterPlugin>();
    if (kind == "shape") return names<ShapePlugin>();
    return {};
}

}  // namespace neepp
