// Safe file paths for every node and CLI that reads or writes a file a request names: inputs must
// be regular files (a FIFO or device would block open() forever), outputs are written atomically
// next to their destination, an existing file is kept unless the caller asks to overwrite it, an
// output never replaces one of the request's inputs, and request paths stay inside configured
// roots. Every refusal is a std::invalid_argument whose message names the path and the reason.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace lfd {

/// Where request paths may point. Empty roots = anywhere (the CLIs: their user owns the shell).
struct PathPolicy {
  /// Absolute folders; a leading "~" is the caller's $HOME. With roots set, ".." is refused too.
  std::vector<std::string> allowed_roots;
};

/// Checks a file to read and returns its canonical path: it exists, is a regular file (checked
/// with stat before anything opens it) and, under roots, lies inside one of them.
std::string checkInputFile(const std::string& path, const PathPolicy& policy = {});

/// Checks a file to write: its folder exists, it lies inside a root, it is not one of `inputs`
/// (same file, also through a link), and if it exists it is a regular file and `overwrite` is set.
/// Returns the absolute path to write.
std::string checkOutputFile(const std::string& path, const PathPolicy& policy, bool overwrite,
                            const std::vector<std::string>& inputs = {});

/// Checks a path a request names for a file that may not exist yet (nor its folder: e.g. a bag the
/// recorder creates with its folders): under roots, no ".." and inside a root once the part that
/// exists is resolved (links followed). Returns the absolute, resolved path.
std::string checkPathInRoots(const std::string& path, const PathPolicy& policy);

/// Writes `path` atomically: `write` fills a temporary file in the same folder, which is then
/// renamed over `path` (readers see the old file or the whole new one, never half of one). Without
/// `overwrite` an existing `path` is kept and the call throws. The temporary is removed on error.
void writeFileAtomically(const std::string& path, bool overwrite,
                         const std::function<void(const std::string& temp_path)>& write);

/// The same for text content.
void writeTextAtomically(const std::string& path, bool overwrite, const std::string& text);

}  // namespace lfd
