// Safe paths: regular-file inputs, roots, "..", no output over an input, atomic writes
// that keep an existing file unless asked to overwrite. Regression: file identities for caches,
// overwrite replaces only lfd's own files, relative request paths refused in services.
#include "lfd_core/io/safe_paths.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <thread>

#include "support/error_of.hpp"

namespace {

namespace fs = std::filesystem;

class SafePaths : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("lfd_safe_paths_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "root" / "sub");
    fs::create_directories(dir_ / "outside");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const fs::path& p, const std::string& text) {
    std::ofstream(p) << text;
    return p.string();
  }
  static std::string read(const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  lfd::PathPolicy rooted() const { return lfd::PathPolicy{{(dir_ / "root").string()}}; }
  // A kind that takes any existing file as lfd's: the tests of all but the recognition itself.
  static lfd::OutputKind anyKind() {
    return {"test output", [](const lfd::InputFile&) { return true; }};
  }

  fs::path dir_;
};

TEST_F(SafePaths, InputMustBeAnExistingRegularFile) {
  const std::string file = write(dir_ / "root" / "a.bag", "x");
  EXPECT_EQ(lfd::checkInputFile(file), fs::canonical(file).string());
  EXPECT_NE(errorOf([&] { lfd::checkInputFile((dir_ / "missing").string()); }).find("No such file"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { lfd::checkInputFile(dir_.string()); }).find("directory"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { lfd::checkInputFile("/dev/zero"); }).find("device"), std::string::npos);
  EXPECT_NE(errorOf([&] { lfd::checkInputFile(""); }).find("empty"), std::string::npos);
}

// A FIFO made open() block forever in the nodes; stat refuses it without opening it.
TEST_F(SafePaths, NamedPipeIsRefusedWithoutBlocking) {
  const std::string fifo = (dir_ / "root" / "pipe.bag").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(errorOf([&] { lfd::checkInputFile(fifo); }).find("named pipe"), std::string::npos);
  EXPECT_NE(
      errorOf([&] { lfd::checkOutputFile(fifo, {}, true, {}, anyKind()); }).find("named pipe"),
      std::string::npos);
}

// Regression: a link to a FIFO is refused at once, with the reason, by the file-access layer.
TEST_F(SafePaths, LinkToNamedPipeIsRefusedAtOnce) {
  const std::string fifo = (dir_ / "root" / "pipe.bag").string();
  const std::string link = (dir_ / "root" / "link.bag").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ASSERT_EQ(::symlink(fifo.c_str(), link.c_str()), 0);
  const auto start = std::chrono::steady_clock::now();
  const std::string error = errorOf([&] { lfd::openInputFile(link, rooted()); });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 1.0);
  EXPECT_NE(error.find("named pipe (FIFO), not a regular file"), std::string::npos) << error;
  EXPECT_NE(error.find("link.bag"), std::string::npos) << error;  // names the user's path
}

// Regression: what the layer returns reaches the checked file, whatever the link points at
// once it was opened (readers open readPath(), never the user's path again).
TEST_F(SafePaths, LinkSwappedAfterOpeningStillReadsTheCheckedFile) {
  const std::string file = write(dir_ / "root" / "a.bag", "the real bag");
  const std::string fifo = (dir_ / "root" / "pipe.bag").string();
  const std::string link = (dir_ / "root" / "link.bag").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ASSERT_EQ(::symlink(file.c_str(), link.c_str()), 0);
  const lfd::InputFile opened = lfd::openInputFile(link, rooted());
  EXPECT_EQ(opened.resolved(), fs::canonical(file).string());
  EXPECT_EQ(opened.size(), 12u);
  fs::remove(link);
  ASSERT_EQ(::symlink(fifo.c_str(), link.c_str()), 0);  // swapped: the link is a FIFO now
  EXPECT_EQ(read(opened.readPath()), "the real bag");
  EXPECT_EQ(read(opened.readPath()), "the real bag");  // every reader that opens it again
}

TEST_F(SafePaths, InputSizeIsBoundedOnTheOpenDescriptor) {
  const std::string file = write(dir_ / "root" / "a.bag", "0123456789");
  EXPECT_EQ(lfd::openInputFile(file, {}, 10).size(), 10u);
  EXPECT_NE(errorOf([&] { lfd::openInputFile(file, {}, 9); }).find("over the limit of 9"),
            std::string::npos);
}

TEST_F(SafePaths, RootsAndParentReferences) {
  const std::string inside = write(dir_ / "root" / "sub" / "a.bag", "x");
  const std::string outside = write(dir_ / "outside" / "b.bag", "x");
  EXPECT_NO_THROW(lfd::checkInputFile(inside, rooted()));
  EXPECT_NE(errorOf([&] { lfd::checkInputFile(outside, rooted()); }).find("allowed_roots"),
            std::string::npos);
  const std::string dotdot = (dir_ / "root" / "sub" / ".." / "sub" / "a.bag").string();
  EXPECT_NE(errorOf([&] { lfd::checkInputFile(dotdot, rooted()); }).find("'..'"),
            std::string::npos);
  EXPECT_NO_THROW(lfd::checkInputFile(dotdot));  // no roots (a CLI): ".." is the user's business
  // A symlink inside the root that points out of it does not pass.
  const fs::path link = dir_ / "root" / "link.bag";
  fs::create_symlink(outside, link);
  EXPECT_NE(errorOf([&] { lfd::checkInputFile(link.string(), rooted()); }).find("allowed_roots"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              lfd::checkOutputFile(outside, rooted(), true, {}, anyKind());
            }).find("allowed_roots"),
            std::string::npos);
  EXPECT_NO_THROW(
      lfd::checkOutputFile((dir_ / "root" / "new.json").string(), rooted(), false, {}, anyKind()));
  // "~" is $HOME.
  EXPECT_NE(errorOf([&] {
              lfd::checkInputFile(inside, lfd::PathPolicy{{"~/lfd_no_such_root"}});
            }).find(std::string(std::getenv("HOME"))),
            std::string::npos);
}

TEST_F(SafePaths, OutputIsNeverAnInputAndKeepsExistingFiles) {
  const std::string bag = write(dir_ / "root" / "demo.bag", "demo");
  const lfd::OutputKind kind = anyKind();
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(bag, {}, true, {bag}, kind); }).find("inputs"),
            std::string::npos);
  // The same file through another spelling or a hard link.
  const std::string spelled = (dir_ / "root" / "sub" / ".." / "demo.bag").string();
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(spelled, {}, true, {bag}, kind); }).find("inputs"),
            std::string::npos);
  const fs::path hard = dir_ / "root" / "hard.json";
  fs::create_hard_link(bag, hard);
  EXPECT_NE(
      errorOf([&] { lfd::checkOutputFile(hard.string(), {}, true, {bag}, kind); }).find("inputs"),
      std::string::npos);
  EXPECT_NE(
      errorOf([&] { lfd::checkOutputFile(hard.string(), {}, false, {}, kind); }).find("exists"),
      std::string::npos);
  EXPECT_NE(errorOf([&] {
              lfd::checkOutputFile((dir_ / "nofolder" / "x").string(), {}, false, {}, kind);
            }).find("does not exist"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              lfd::checkOutputFile(dir_.string() + "/", {}, true, {}, kind);
            }).find("folder"),
            std::string::npos);
}

TEST_F(SafePaths, AtomicWriteKeepsOrReplaces) {
  const std::string out = write(dir_ / "root" / "lib.json", "old");
  const lfd::OutputKind kind = anyKind();
  EXPECT_NE(errorOf([&] { lfd::writeTextAtomically(out, false, kind, "new"); }).find("exists"),
            std::string::npos);
  EXPECT_EQ(read(out), "old");
  lfd::writeTextAtomically(out, true, kind, "new");
  EXPECT_EQ(read(out), "new");
  // A failing writer leaves the old file and no temporary behind.
  EXPECT_THROW(lfd::writeFileAtomically(out, true, kind,
                                        [](const std::string& temp) {
                                          std::ofstream(temp) << "half";
                                          throw std::runtime_error("writer failed");
                                        }),
               std::runtime_error);
  EXPECT_EQ(read(out), "new");
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "root")) files += e.is_regular_file();
  EXPECT_EQ(files, 1u);
  const std::string fresh = (dir_ / "root" / "fresh.json").string();
  lfd::writeTextAtomically(fresh, false, kind, "first");
  EXPECT_EQ(read(fresh), "first");
}

// Regression: overwrite: true replaced any regular file under the roots (a test .bashrc went).
// An existing file is replaced only when it is recognisably lfd's own product of the output's
// kind; anything else is kept, and the error names the path and says lfd did not write it.
TEST_F(SafePaths, OverwriteReplacesOnlyFilesLfdWroteOfThatKind) {
  const std::string bashrc = write(dir_ / "root" / ".bashrc", "export PATH=$HOME/bin:$PATH\n");
  const lfd::OutputKind library = lfd::jsonOutput("skill library", "lfd_skill_library");
  const std::string error =
      errorOf([&] { lfd::checkOutputFile(bashrc, rooted(), true, {}, library); });
  EXPECT_NE(error.find(".bashrc"), std::string::npos) << error;
  EXPECT_NE(error.find("was not written by lfd as a skill library"), std::string::npos) << error;
  // The writer checks again itself: a caller that skipped checkOutputFile cannot replace it.
  EXPECT_NE(errorOf([&] {
              lfd::writeTextAtomically(bashrc, true, library, "{}");
            }).find("was not written by lfd"),
            std::string::npos);
  EXPECT_EQ(read(bashrc), "export PATH=$HOME/bin:$PATH\n");

  // JSON: the format marker decides, wherever it is among the top-level members.
  const std::string ours = write(dir_ / "root" / "lib.json",
                                 R"({"a": [1, {"format": "x"}], "format": "lfd_skill_library"})");
  EXPECT_NO_THROW(lfd::checkOutputFile(ours, rooted(), true, {}, library));
  const std::string other = write(dir_ / "root" / "other.json", R"({"format": "geojson"})");
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(other, rooted(), true, {}, library); }), "");
  const std::string nested =
      write(dir_ / "root" / "nested.json", R"({"x": {"format": "lfd_skill_library"}})");
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(nested, rooted(), true, {}, library); }), "");
  EXPECT_NE(errorOf([&] {
              lfd::checkOutputFile(write(dir_ / "root" / "array.json", R"(["format"])"), rooted(),
                                   true, {}, library);
            }),
            "");
  // Without any marker: only a whole object with the members lfd always wrote there.
  const lfd::OutputKind result =
      lfd::jsonOutput("segmentation result", "lfd_segmentation", {"success"});
  const std::string old_result =
      write(dir_ / "root" / "old.json", R"({"success": true, "demos": []})");
  EXPECT_NO_THROW(lfd::checkOutputFile(old_result, rooted(), true, {}, result));
  const std::string cut = write(dir_ / "root" / "cut.json", R"({"success": true, "demos": [)");
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(cut, rooted(), true, {}, result); }), "");
  const std::string plain = write(dir_ / "root" / "plain.json", R"({"name": "x"})");
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(plain, rooted(), true, {}, result); }), "");

  // Bags by rosbag's version line, CSVs by the first line lfd writes.
  const lfd::OutputKind bag = lfd::bagOutput();
  EXPECT_NO_THROW(lfd::checkOutputFile(write(dir_ / "root" / "a.bag", "#ROSBAG V2.0\nE..."),
                                       rooted(), true, {}, bag));
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(bashrc, rooted(), true, {}, bag); }), "");
  const lfd::OutputKind csv = lfd::textOutput("trajectory CSV", "# lfd trajectory");
  const std::string traj = write(dir_ / "root" / "t.csv", "# lfd trajectory\nt,x\n0,1\n");
  lfd::writeTextAtomically(traj, true, csv, "# lfd trajectory\nt,x\n0,2\n");
  EXPECT_EQ(read(traj), "# lfd trajectory\nt,x\n0,2\n");
  const std::string foreign = write(dir_ / "root" / "u.csv", "t,x\n0,1\n");
  EXPECT_NE(errorOf([&] { lfd::checkOutputFile(foreign, rooted(), true, {}, csv); }), "");
}

// Regression: service request paths must be absolute (a relative one resolves against the node's
// working directory); the CLIs keep taking relative paths.
TEST_F(SafePaths, RelativeRequestPathsAreRefusedUnderRequireAbsolute) {
  lfd::PathPolicy service;
  service.require_absolute = true;
  const std::string error =
      errorOf([&] { lfd::checkRequestPath("bag_paths[1]", "demo.bag", service); });
  EXPECT_NE(error.find("bag_paths[1]: path 'demo.bag' is relative"), std::string::npos) << error;
  EXPECT_NE(error.find("absolute path"), std::string::npos) << error;
  EXPECT_EQ(errorOf([&] { lfd::checkRequestPath("bag_paths[0]", "/tmp/demo.bag", service); }), "");
  EXPECT_EQ(errorOf([&] { lfd::checkRequestPath("bag_paths[0]", "demo.bag", {}); }), "");
  // The same rule in every path check, as a backstop.
  const std::string file = write(dir_ / "root" / "a.bag", "x");
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_ / "root");
  EXPECT_NE(errorOf([&] { lfd::openInputFile("a.bag", service); }).find("is relative"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              lfd::checkOutputFile("b.json", service, false, {}, anyKind());
            }).find("is relative"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { lfd::checkPathInRoots("c.bag", service); }).find("is relative"),
            std::string::npos);
  EXPECT_EQ(lfd::openInputFile("a.bag").resolved(), fs::canonical(file).string());  // a CLI's
  fs::current_path(cwd);
}

// Regression: a bag replaced by another file of the same size and modification time looked the
// same to a cache keyed by path, size and mtime. The identity of an open file tells them apart.
TEST_F(SafePaths, IdentityTellsAReplacedFileOfTheSameSizeAndTime) {
  const std::string bag = write(dir_ / "root" / "a.bag", "the real bag");
  const lfd::FileIdentity before = lfd::openInputFile(bag).identity();
  EXPECT_EQ(before, lfd::openInputFile(bag).identity());
  EXPECT_EQ(before.size, 12u);
  struct stat st {};
  ASSERT_EQ(::stat(bag.c_str(), &st), 0);
  const struct timespec times[2] = {st.st_atim, st.st_mtim};
  // A same-size file with the old times, renamed over the bag (touch -r old new; mv new bag).
  const std::string fake = write(dir_ / "root" / "fake", "corrupt data");
  ASSERT_EQ(::utimensat(AT_FDCWD, fake.c_str(), times, 0), 0);
  fs::rename(fake, bag);
  const lfd::FileIdentity renamed = lfd::openInputFile(bag).identity();
  EXPECT_EQ(renamed.size, before.size);
  EXPECT_EQ(renamed.mtime_sec, before.mtime_sec);
  EXPECT_EQ(renamed.mtime_nsec, before.mtime_nsec);
  EXPECT_FALSE(renamed == before);
  // Rewritten in place (same inode) with its times set back: the change time moved. (Apart from
  // the rename by more than the kernel's coarse clock step, a few ms.)
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  write(bag, "other bytes!");
  ASSERT_EQ(::utimensat(AT_FDCWD, bag.c_str(), times, 0), 0);
  const lfd::FileIdentity rewritten = lfd::openInputFile(bag).identity();
  EXPECT_EQ(rewritten.inode, renamed.inode);
  EXPECT_EQ(rewritten.mtime_nsec, before.mtime_nsec);
  EXPECT_FALSE(rewritten == renamed);
}

}  // namespace
