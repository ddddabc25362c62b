// Problems of a scene, for `neepp check`: while a scene is checked the loader records each problem here
// and goes on past it (the broken element is left out, a shape keeps a default BSDF), so that one run
// lists them all; while it is loaded, the first error stops it and warnings go to stderr.
#pragma once
#include <string>
#include <vector>
#include "neepp/io/scene_error.h"

namespace neepp {

struct SceneProblem {
    std::string file;
    int line = 0;      // 0: no single line
    bool error = true;  // false: a warning (the scene renders, perhaps not as intended)
    std::string problem;
    // "FILE:LINE: error: problem", as compilers write it.
    std::string text() const;
};

namespace loader {

// While it lives, the loader on this thread records problems in `list` instead of stopping at them.
class CheckingScope {
public:
    explicit CheckingScope(std::vector<SceneProblem> &list);
    ~CheckingScope();
    CheckingScope(const CheckingScope &) = delete;
    CheckingScope &operator=(const CheckingScope &) = delete;

private:
    std::vector<SceneProblem> *previous_;
};

bool checking();
// A warning: recorded when checking, else written to stderr as "neepp: warning: FILE:LINE: text".
void warn(const std::string &file, int line, const std::string &text);
void record(const SceneError &e);
// Runs f; when checking, a SceneError it throws is recorded and false returned (the caller goes on
// without what f would have made); when loading, the error propagates.
template <typename F> bool attempt(F &&f) {
    if (!checking()) {
        f();
        return true;
    }
    try {
        f();
        return true;
    } catch (const SceneError &e) {
        record(e);
        return false;
    }
}

}  // namespace loader
}  // namespace neepp
