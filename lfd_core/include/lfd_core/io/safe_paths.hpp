// Safe file paths for every node and CLI that reads or writes a file a request names: inputs must
// be regular files (a FIFO or device would block open() forever), outputs are written atomically
// next to their destination, an existing file is kept unless the caller asks to overwrite it and
// it is an lfd product of the output's kind, an output never replaces one of the request's
// inputs, and request paths stay inside configured roots (and are absolute in services). Every
// refusal is a std::invalid_argument whose message names the path and the reason.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace lfd {

/// Where request paths may point. Empty roots = anywhere (the CLIs: their user owns the shell).
struct PathPolicy {
  /// Absolute folders; a leading "~" is the caller's $HOME. With roots set, ".." is refused too.
  std::vector<std::string> allowed_roots;
  /// Relative paths refused (services and actions): a node resolves them against its own working
  /// directory, which its client neither sees nor chose. The CLIs accept them (the shell's).
  bool require_absolute = false;
};

/// Refuses a request path the policy does not accept as written (relative under
/// require_absolute): "<field>: path '...' is relative; ...". `field` names the request field
/// ("bag_paths[2]"). Services call it on every path field before any work.
void checkRequestPath(const std::string& field, const std::string& path, const PathPolicy& policy);

/// What identifies a file's content without reading it, from the fstat of an open descriptor:
/// device and inode (a file renamed over the path is another inode), size, and modification and
/// status-change times in nanoseconds. A user can set mtime back (touch -r) but not ctime, which
/// every write and rename of the inode moves.
struct FileIdentity {
  std::uint64_t device = 0, inode = 0, size = 0;
  std::int64_t mtime_sec = 0, mtime_nsec = 0, ctime_sec = 0, ctime_nsec = 0;
  /// "dev:ino:size:mtime.ns:ctime.ns", for cache keys.
  std::string key() const;
  bool operator==(const FileIdentity& other) const { return key() == other.key(); }
};

/// A file to read, opened once (checking a path and opening it again by name let a link
/// swapped in between to a FIFO hang open()). Readers that take a file name (rosbag, ifstream,
/// yaml-cpp) open `readPath()`, the still-open descriptor's /proc entry: it always reaches the
/// file that was checked, whatever the user's path points at by then. Move-only; closes on
/// destruction, so keep it alive while the reader opens `readPath()`.
class InputFile {
 public:
  InputFile(InputFile&& other) noexcept;
  InputFile& operator=(InputFile&& other) noexcept;
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  ~InputFile();

  /// The canonical path the user's path resolved to (for messages and comparisons).
  const std::string& resolved() const { return resolved_; }
  /// "/proc/self/fd/N": the name to hand to readers.
  std::string readPath() const;
  std::uint64_t size() const { return identity_.size; }
  /// The fstat of the descriptor when it was opened: the file that readPath() reads.
  const FileIdentity& identity() const { return identity_; }
  int fd() const { return fd_; }

 private:
  friend InputFile openInputFile(const std::string&, const PathPolicy&, std::uint64_t);
  InputFile(int fd, std::string resolved);
  int fd_ = -1;
  std::string resolved_;
  FileIdentity identity_;
};

/// Opens a file to read: the path is resolved once (realpath) and checked against the roots, the
/// resolved path is opened without following a final link and without blocking
/// (O_NOFOLLOW | O_NONBLOCK: a FIFO without a writer opens at once), and the open descriptor must
/// be a regular file of at most `max_bytes` (0 = no bound) that still is the resolved path.
/// Throws std::invalid_argument naming the path and the reason.
InputFile openInputFile(const std::string& path, const PathPolicy& policy = {},
                        std::uint64_t max_bytes = 0);

/// Checks a file to read and returns its canonical path (openInputFile, then closed): for early
/// checks of a whole request; readers open their file with openInputFile themselves.
std::string checkInputFile(const std::string& path, const PathPolicy& policy = {});

/// The kind of file an output is. `overwrite` replaces an existing file only when it is
/// recognisably an lfd product of that kind (overwrite: true replaced a test .bashrc,
/// any regular file under the roots could go). The predicate gets the existing file, opened by
/// the file-access layer, and says whether lfd wrote it.
struct OutputKind {
  std::string name;  ///< "skill library", for messages
  std::function<bool(const InputFile& existing)> written_by_lfd;
};

/// A ROS bag: the file starts with rosbag's version line "#ROSBAG V2.0\n".
OutputKind bagOutput();
/// A text file lfd writes with `first_line` (e.g. a CSV's "# lfd ..." comment line) first.
OutputKind textOutput(const std::string& name, const std::string& first_line);
/// A JSON object whose top-level "format" is `format`. An older file without any "format" member
/// counts when it has every one of `legacy_members` at its top level (what lfd always wrote
/// there). Read as a stream (nothing is kept), so a large file costs no memory.
OutputKind jsonOutput(const std::string& name, const std::string& format,
                      const std::vector<std::string>& legacy_members = {});

/// Checks a file to write: its folder exists, it lies inside a root, it is not one of `inputs`
/// (same file, also through a link), and if it exists it is a regular file, `overwrite` is set
/// and `kind` recognises it as lfd's. Returns the absolute path to write.
std::string checkOutputFile(const std::string& path, const PathPolicy& policy, bool overwrite,
                            const std::vector<std::string>& inputs, const OutputKind& kind);

/// Checks a path a request names for a file that may not exist yet (nor its folder: e.g. a bag the
/// recorder creates with its folders): under roots, no ".." and inside a root once the part that
/// exists is resolved (links followed). Returns the absolute, resolved path.
std::string checkPathInRoots(const std::string& path, const PathPolicy& policy);

/// Writes `path` atomically: `write` fills a temporary file in the same folder, which is then
/// renamed over `path` (readers see the old file or the whole new one, never half of one). Without
/// `overwrite` an existing `path` is kept and the call throws; with it, an existing `path` is
/// replaced only when `kind` recognises it (checked again just before the rename). The temporary
/// is removed on error.
void writeFileAtomically(const std::string& path, bool overwrite, const OutputKind& kind,
                         const std::function<void(const std::string& temp_path)>& write);

/// The same for text content.
void writeTextAtomically(const std::string& path, bool overwrite, const OutputKind& kind,
                         const std::string& text);

}  // namespace lfd
