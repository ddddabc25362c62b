#include "neepp/loader/problems.h"

#include <fmt/core.h>

namespace neepp {

std::string SceneProblem::text() const {
    return file + (line > 0 ? ":" + std::to_string(line) : "") + (error ? ": error: " : ": warning: ") + problem;
}

namespace loader {

namespace {
thread_local std::vector<SceneProblem> *t_problems = nullptr;
}

CheckingScope::CheckingScope(std::vector<SceneProblem> &list) : previous_(t_problems) { t_problems = &list; }
CheckingScope::~CheckingScope() { t_problems = previous_; }

bool checking() { return t_problems != nullptr; }

void warn(const std::string &file, int line, const std::string &text) {
    if (t_problems) {
        t_problems->push_back({file, line, false, text});
        return;
    }
    fmt::print(stderr, "neepp: warning: {}{}: {}\n", file, line > 0 ? ":" + std::to_string(line) : "", text);
}

void record(const SceneError &e) {
    if (!t_problems) return;
    // An element that failed is tried again by everything that refers to it (a medium or BSDF shared by
    // several shapes): its error is listed once.
    for (const SceneProblem &p : *t_problems)
        if (p.error && p.file == e.file && p.line == e.line && p.problem == e.problem) return;
    t_problems->push_back({e.file, e.line, true, e.problem});
}

}  // namespace loader
}  // namespace neepp
