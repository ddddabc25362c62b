// Files that are never seen half-written: a render killed at any moment (SIGKILL, power loss, a full
// disk) leaves under an output's name either the previous complete file or the new complete one.
#pragma once
#include <functional>
#include <string>

namespace neepp {

// Calls write(temporary) to write the whole file to a temporary path in the target's folder (the same
// file system, so the rename is atomic), flushes it to disk, then renames it over path. On any failure
// the temporary file is removed and the target left as it was; write's exceptions propagate, and a
// failed flush or rename throws std::runtime_error naming path. The temporary is ".NAME.PID.tmp"; those of
// NAME that processes no longer running left (a render killed by SIGKILL) are removed first.
void write_file_atomically(const std::string &path, const std::function<void(const std::string &temporary)> &write);

// The same for a file whose whole content is in memory (statistics JSON, visibility maps).
void write_file_atomically(const std::string &path, const std::string &content);

// Removes the temporaries of path that processes no longer running left (as each write does first): for
// a file that is removed rather than written again (a finished render's checkpoint).
void remove_stale_temporaries(const std::string &path);

}  // namespace neepp
