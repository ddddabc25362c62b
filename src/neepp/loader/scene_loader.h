// Turns a Mitsuba 3 XML scene file into a Scene: the XML tree (io/xml_tree) is read first, then each
// node becomes a shape, BSDF, texture, light, camera or render setting. Nothing outside this folder
// knows about XML.
#pragma once
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>
#include "neepp/loader/problems.h"
#include "neepp/scene/scene.h"

namespace neepp {

// defines: -D name=value overrides of the file's <default> parameters; one the scene never substitutes
// is refused (Mitsuba 3's "unused parameters"), unless named in may_be_unused (values the caller adds on
// its own, such as the CLI's --spp, which a scene without $spp simply does not take).
// Throws SceneError ("file:line: problem") for any malformed or unsupported content.
std::unique_ptr<Scene> load_scene(const std::string &path, const std::map<std::string, std::string> &defines = {},
                                  const std::set<std::string> &may_be_unused = {});

// Every problem of a scene at once, without building it for rendering (neepp check): errors load_scene
// would stop at, and warnings (properties nothing reads, elements left out), in the order met. The loader
// goes past each: a broken element is left out, a shape whose BSDF is broken keeps a default one.
std::vector<SceneProblem> check_scene(const std::string &path, const std::map<std::string, std::string> &defines = {},
                                     const std::set<std::string> &may_be_unused = {});

}  // namespace neepp
