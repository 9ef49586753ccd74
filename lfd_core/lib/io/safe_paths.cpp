#include "lfd_core/io/safe_paths.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include "lfd_core/io/user_text.hpp"

namespace lfd {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw std::invalid_argument("path " + lfd::quoted(path) + ": " + why);
}

std::string expandHome(const std::string& root) {
  if (root.empty() || root[0] != '~') return root;
  const char* home = std::getenv("HOME");
  if (!home || !*home)
    throw std::invalid_argument("allowed root " + lfd::quoted(root) + " needs $HOME");
  return std::string(home) + root.substr(1);
}

bool hasParentReference(const std::string& path) {
  for (const fs::path& part : fs::path(path)) {
    if (part == "..") return true;
  }
  return false;
}

bool isInside(const fs::path& resolved, const fs::path& root) {
  auto r = root.begin();
  auto p = resolved.begin();
  for (; r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == resolved.end() || *p != *r) return false;
  }
  return true;
}

// `resolved` is canonical (symlinks followed), so a link out of a root does not pass.
void checkRoots(const std::string& path, const fs::path& resolved, const PathPolicy& policy) {
  if (policy.allowed_roots.empty()) return;
  std::string roots;
  for (const std::string& root : policy.allowed_roots) {
    const fs::path r = fs::weakly_canonical(fs::absolute(expandHome(root)));
    if (isInside(resolved, r)) return;
    roots += (roots.empty() ? "" : ", ") + r.string();
  }
  refuse(path, "outside the allowed roots (allowed_roots: " + roots + ")");
}

constexpr const char* kRelativeWhy =
    "is relative; a service request needs an absolute path (the node resolves a relative one "
    "against its own working directory, not the caller's)";

// Checked first: a relative request path, or one with "..", is refused whether or not its target
// exists.
void checkParentReferences(const std::string& path, const PathPolicy& policy) {
  if (policy.require_absolute && !fs::path(path).is_absolute()) refuse(path, kRelativeWhy);
  if (!policy.allowed_roots.empty() && hasParentReference(path))
    refuse(path, "'..' is not allowed in request paths");
}

const char* typeName(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a named pipe (FIFO)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// realpath: every link followed, once; the result names no link.
std::string resolvedPath(const std::string& path) {
  char* resolved = ::realpath(path.c_str(), nullptr);
  if (!resolved) refuse(path, std::strerror(errno));
  std::string result(resolved);
  std::free(resolved);
  return result;
}

// What the kernel says an open descriptor is: its path now.
std::string descriptorPath(int fd) {
  std::error_code ec;
  const fs::path target = fs::read_symlink("/proc/self/fd/" + std::to_string(fd), ec);
  return ec ? std::string() : target.string();
}

FileIdentity identityOf(const struct stat& st) {
  FileIdentity id;
  id.device = static_cast<std::uint64_t>(st.st_dev);
  id.inode = static_cast<std::uint64_t>(st.st_ino);
  id.size = static_cast<std::uint64_t>(st.st_size);
  id.mtime_sec = st.st_mtim.tv_sec;
  id.mtime_nsec = st.st_mtim.tv_nsec;
  id.ctime_sec = st.st_ctim.tv_sec;
  id.ctime_nsec = st.st_ctim.tv_nsec;
  return id;
}

// An existing output may be replaced only when its kind recognises it as lfd's own product.
void checkReplaceable(const std::string& path, const std::string& resolved,
                      const OutputKind& kind) {
  bool ours = false;
  try {
    ours = kind.written_by_lfd && kind.written_by_lfd(openInputFile(resolved));
  } catch (const std::exception& e) {
    refuse(path, "exists and cannot be checked (" + std::string(e.what()) + "); it is kept");
  }
  if (!ours) {
    refuse(path, "exists and was not written by lfd as a " + kind.name +
                     "; it is kept (overwrite replaces only lfd's own " + kind.name +
                     " files): remove it or choose another path");
  }
}

}  // namespace

void checkRequestPath(const std::string& field, const std::string& path, const PathPolicy& policy) {
  if (policy.require_absolute && !fs::path(path).is_absolute())
    throw std::invalid_argument(field + ": path " + lfd::quoted(path) + " " + kRelativeWhy);
}

std::string FileIdentity::key() const {
  return std::to_string(device) + ":" + std::to_string(inode) + ":" + std::to_string(size) + ":" +
         std::to_string(mtime_sec) + "." + std::to_string(mtime_nsec) + ":" +
         std::to_string(ctime_sec) + "." + std::to_string(ctime_nsec);
}

InputFile::InputFile(int fd, std::string resolved) : fd_(fd), resolved_(std::move(resolved)) {}

InputFile::InputFile(InputFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      resolved_(std::move(other.resolved_)),
      identity_(other.identity_) {}

InputFile& InputFile::operator=(InputFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    resolved_ = std::move(other.resolved_);
    identity_ = other.identity_;
  }
  return *this;
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

std::string InputFile::readPath() const {
  return "/proc/self/fd/" + std::to_string(fd_);
}

InputFile openInputFile(const std::string& path, const PathPolicy& policy,
                        std::uint64_t max_bytes) {
  if (path.empty()) throw std::invalid_argument("empty file path");
  checkParentReferences(path, policy);
  const std::string resolved = resolvedPath(path);
  checkRoots(path, resolved, policy);
  struct stat st {};
  // stat opens nothing: a device is refused before open() could touch it (fstat below decides).
  if (::stat(resolved.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    refuse(path, std::string(typeName(st.st_mode)) + ", not a regular file");
  // The final link was resolved above; one swapped in since is refused (ELOOP), never followed.
  const int fd = ::open(resolved.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    refuse(path, errno == ELOOP ? "changed into a link while opening it" : std::strerror(errno));
  InputFile file(fd, resolved);  // closes the descriptor on every refusal below
  if (::fstat(fd, &st) != 0) refuse(path, std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    refuse(path, std::string(typeName(st.st_mode)) + ", not a regular file");
  // A folder on the way swapped for a link since realpath would lead outside the roots.
  if (descriptorPath(fd) != resolved) refuse(path, "changed while opening it");
  const std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
  if (max_bytes > 0 && size > max_bytes) {
    refuse(path, std::to_string(size) + " bytes, over the limit of " + std::to_string(max_bytes));
  }
  // Readers block as usual on a regular file; O_NONBLOCK was only for the open itself.
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  file.identity_ = identityOf(st);
  return file;
}

std::string checkInputFile(const std::string& path, const PathPolicy& policy) {
  return openInputFile(path, policy).resolved();
}

std::string checkOutputFile(const std::string& path, const PathPolicy& policy, bool overwrite,
                            const std::vector<std::string>& inputs, const OutputKind& kind) {
  if (path.empty()) throw std::invalid_argument("empty output path");
  checkParentReferences(path, policy);
  const fs::path absolute = fs::absolute(path);
  if (!absolute.has_filename()) refuse(path, "names a folder, not a file");
  const fs::path folder = absolute.parent_path();
  struct stat dir {};
  if (::stat(folder.c_str(), &dir) != 0 || !S_ISDIR(dir.st_mode)) {
    refuse(path, "its folder " + folder.string() + " does not exist");
  }
  const fs::path resolved = fs::canonical(folder) / absolute.filename();
  checkRoots(path, resolved, policy);
  struct stat out {};
  const bool exists = ::stat(resolved.c_str(), &out) == 0;
  for (const std::string& input : inputs) {
    if (input.empty()) continue;  // names no file
    struct stat in {};
    const bool same_inode = exists && ::stat(input.c_str(), &in) == 0 && in.st_dev == out.st_dev &&
                            in.st_ino == out.st_ino;
    std::error_code ec;
    const fs::path input_path = fs::weakly_canonical(fs::absolute(input, ec), ec);
    if (same_inode || (!ec && input_path == resolved)) {
      refuse(path, "is one of the request's inputs; refusing to overwrite it");
    }
  }
  if (exists && !S_ISREG(out.st_mode))
    refuse(path, std::string("exists and is ") + typeName(out.st_mode));
  if (exists && !overwrite) refuse(path, "exists; set overwrite to replace it");
  if (exists) checkReplaceable(path, resolved.string(), kind);
  return resolved.string();
}

std::string checkPathInRoots(const std::string& path, const PathPolicy& policy) {
  if (path.empty()) throw std::invalid_argument("empty path");
  checkParentReferences(path, policy);
  const fs::path resolved = fs::weakly_canonical(fs::absolute(path));
  checkRoots(path, resolved, policy);
  return resolved.string();
}

void writeFileAtomically(const std::string& path, bool overwrite, const OutputKind& kind,
                         const std::function<void(const std::string& temp_path)>& write) {
  const fs::path target = fs::absolute(path);
  std::string temp =
      (target.parent_path() / ("." + target.filename().string() + ".tmp.XXXXXX")).string();
  const int fd = ::mkstemp(temp.data());
  if (fd < 0) refuse(path, std::string("cannot create a temporary file: ") + std::strerror(errno));
  ::fchmod(fd, 0644);  // mkstemp's 0600 would hide outputs from other users
  ::close(fd);
  try {
    write(temp);
    const int sync_fd = ::open(temp.c_str(), O_RDONLY);
    if (sync_fd >= 0) {  // the data reaches the disk before the name points at it
      ::fsync(sync_fd);
      ::close(sync_fd);
    }
    int rc = 0;
    struct stat existing {};
    if (overwrite && ::stat(target.c_str(), &existing) == 0) {
      // Checked again as late as possible: what the rename replaces must be lfd's own.
      if (!S_ISREG(existing.st_mode))
        refuse(path, std::string("exists and is ") + typeName(existing.st_mode));
      checkReplaceable(path, target.string(), kind);
    }
    if (overwrite) {
      rc = ::rename(temp.c_str(), target.c_str());
    } else {
      // No-clobber rename: a file created since the checks is kept, never replaced.
      rc = ::renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE);
      if (rc != 0 && errno == EINVAL) {  // a file system without RENAME_NOREPLACE
        rc = ::link(temp.c_str(), target.c_str());
        if (rc == 0) ::unlink(temp.c_str());
      }
    }
    if (rc != 0) {
      refuse(path, errno == EEXIST ? "exists; set overwrite to replace it"
                                   : std::string("cannot move the finished file in place: ") +
                                         std::strerror(errno));
    }
  } catch (...) {
    ::unlink(temp.c_str());
    throw;
  }
}

void writeTextAtomically(const std::string& path, bool overwrite, const OutputKind& kind,
                         const std::string& text) {
  writeFileAtomically(path, overwrite, kind, [&](const std::string& temp) {
    FILE* f = std::fopen(temp.c_str(), "w");
    if (!f) refuse(path, std::string("cannot write: ") + std::strerror(errno));
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !ok) refuse(path, "write failed (disk full?)");
  });
}

}  // namespace lfd
