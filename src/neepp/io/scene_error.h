// The one exception type for everything that is wrong with a scene or the files it references.
#pragma once
#include <stdexcept>
#include <string>

namespace neepp {

// what() reads "FILE:LINE: problem" (or "FILE: problem" when no line applies), the form compilers
// use, so that editors and terminals can jump to the offending spot.
struct SceneError : std::runtime_error {
    std::string file;
    int line;  // 1-based; 0 when the problem has no single line (missing file, truncated binary)
    std::string problem;

    SceneError(const std::string &file_, int line_, const std::string &problem_)
        : std::runtime_error(format(file_, line_, problem_)), file(file_), line(line_), problem(problem_) {}
    SceneError(const std::string &file_, const std::string &problem_) : SceneError(file_, 0, problem_) {}

private:
    static std::string format(const std::string &file, int line, const std::string &problem) {
        std::string s = file;
        if (line > 0) s.append(":").append(std::to_string(line));
        return s.append(": ").append(problem);
    }
};

}  // namespace neepp
