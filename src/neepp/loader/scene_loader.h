// Turns a Mitsuba 3 XML scene file into a Scene: the XML tree (io/xml_tree) is read first, then each
// node becomes a shape, BSDF, texture, light, camera or render setting. Nothing outside this folder
// knows about XML.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>
#include "neepp/loader/problems.h"
#include "neepp/scene/scene.h"

namespace neepp {

// defines: -D name=value overrides of the file's <default> parameters.
// Throws SceneError ("file:line: problem") for any malformed or unsupported content.
std::unique_ptr<Scene> load_scene(const std::string &path, const std::map<std::string, std::string> &defines = {});

// Every problem of a scene at once, without building it for rendering (neepp check): errors load_scene
// would stop at, and warnings (properties nothing reads, elements left out), in the order met. The loader
// goes past each: a broken element is left out, a shape whose BSDF is broken keeps a default one.
std::vector<SceneProblem> check_scene(const std::string &path, const std::map<std::string, std::string> &defines = {});

}  // namespace neepp
