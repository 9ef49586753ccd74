// dmp_tool CLI path: learn from a temp CSV, roll out to CSV with a new goal, generalize, errors.
#include "lfd_dmp/dmp_tool.hpp"
#include "lfd_dmp/skill_library.hpp"
#include "lfd_dmp/trajectory_csv.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <iterator>
#include <sstream>

namespace {

std::string tempPath(const std::string& name) {
  return ::testing::TempDir() + "/lfd_dmp_tool_" + std::to_string(::getpid()) + "_" + name;
}

// t, x, y, z, qw, qx, qy, qz, gripper; reach toward goal_x.
std::string writeDemoCsv(const std::string& name, double goal_x, int rows = 400) {
  const std::string path = tempPath(name);
  std::ofstream out(path);
  out << "t,x,y,z,qw,qx,qy,qz,gripper\n";
  for (int i = 0; i < rows; ++i) {
    const double t = 2.0 * i / (rows - 1);
    const double s = t / 2.0;
    const double mj = 10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.5 * mj, Eigen::Vector3d::UnitY()));
    out << t << "," << 0.3 + (goal_x - 0.3) * mj << "," << 0.05 * std::sin(M_PI * s) << ","
        << 0.8 + 0.1 * std::pow(std::sin(M_PI * mj), 2) << "," << q.w() << "," << q.x() << ","
        << q.y() << "," << q.z() << "," << 0.08 - 0.08 * mj << "\n";
  }
  return path;
}

int run(const std::vector<std::string>& args, std::string* out_text = nullptr,
        std::string* err_text = nullptr) {
  std::ostringstream out, err;
  const int rc = lfd_dmp::runDmpTool(args, out, err);
  if (out_text) *out_text = out.str();
  if (err_text) *err_text = err.str();
  return rc;
}

TEST(DmpTool, LearnThenRolloutToANewGoal) {
  const std::string csv = writeDemoCsv("demo.csv", 0.6);
  const std::string json = tempPath("skill.json");
  const std::string traj_csv = tempPath("traj.csv");
  std::string out, err;
  ASSERT_EQ(run({"learn", "--csv", csv, "--out", json, "--task", "reach"}, &out, &err), 0) << err;
  const lfd_dmp::SkillLibrary lib = lfd_dmp::loadSkillLibrary(json);
  EXPECT_EQ(lib.task, "reach");
  EXPECT_EQ(lib.position_names, (std::vector<std::string>{"x", "y", "z"}));
  ASSERT_EQ(lib.segments.size(), 1u);
  ASSERT_TRUE(lib.segments[0].demos[0].dmp.orientation.has_value());
  ASSERT_TRUE(lib.segments[0].demos[0].dmp.gripper.has_value());

  ASSERT_EQ(run({"rollout", "--library", json, "--out", traj_csv, "--goal", "0.7,0.02,0.85",
                 "--goal-gripper", "0.01", "--dt", "0.005", "--duration", "3.0"},
                &out, &err),
            0)
      << err;
  const lfd_dmp::CsvTrajectory traj = lfd_dmp::readTrajectoryCsv(traj_csv);
  EXPECT_EQ(traj.position_names, (std::vector<std::string>{"x", "y", "z"}));
  EXPECT_EQ(traj.demo.times.size(), 601);
  EXPECT_NEAR(traj.demo.times[600], 3.0, 1e-9);
  const Eigen::Vector3d end = traj.demo.positions.bottomRows(1).transpose();
  EXPECT_LT((end - Eigen::Vector3d(0.7, 0.02, 0.85)).norm(), 1e-3);
  EXPECT_NEAR(traj.demo.gripper[600], 0.01, 1e-3);
  EXPECT_EQ(traj.demo.quaternions.cols(), 4);
  // Reproducing the demo itself: the rolled-out CSV matches the input CSV.
  std::ostringstream dt;
  dt.precision(17);
  dt << 2.0 / 399;
  ASSERT_EQ(run({"rollout", "--library", json, "--out", traj_csv, "--dt", dt.str(), "--overwrite"}),
            0);
  const lfd_dmp::CsvTrajectory again = lfd_dmp::readTrajectoryCsv(traj_csv);
  const lfd_dmp::CsvTrajectory demo = lfd_dmp::readTrajectoryCsv(csv);
  ASSERT_EQ(again.demo.positions.rows(), demo.demo.positions.rows());
  EXPECT_LT((again.demo.positions - demo.demo.positions).cwiseAbs().maxCoeff(), 1e-3);
  for (const auto& p : {csv, json, traj_csv}) std::remove(p.c_str());
}

// Regression: `dmp_tool learn --basis 300` crashed (Eigen LDLT under -march=native with pinned
// alignment). 300 and 1000 basis functions (1000 > the demo's 1200 samples / 2) must learn, save,
// load and reproduce the demo.
TEST(DmpTool, LearnsWithHundredsOfBasisFunctions) {
  const std::string csv = writeDemoCsv("many_basis.csv", 0.6, 1200);
  const std::string traj_csv = tempPath("many_basis_traj.csv");
  for (const std::string basis : {"300", "1000"}) {
    const std::string json = tempPath("many_basis_" + basis + ".json");
    std::string out, err;
    ASSERT_EQ(run({"learn", "--csv", csv, "--out", json, "--basis", basis}, &out, &err), 0)
        << basis << ": " << err;
    const lfd_dmp::SkillLibrary lib = lfd_dmp::loadSkillLibrary(json);
    ASSERT_EQ(lib.segments.size(), 1u);
    const lfd::PositionDmp& p = *lib.segments[0].demos[0].dmp.position;
    EXPECT_EQ(p.weights().rows(), std::stoi(basis));
    EXPECT_TRUE(p.weights().allFinite());
    std::ostringstream dt;
    dt.precision(17);
    dt << 2.0 / 1199;
    ASSERT_EQ(
        run({"rollout", "--library", json, "--out", traj_csv, "--dt", dt.str(), "--overwrite"},
            &out, &err),
        0)
        << err;
    const lfd_dmp::CsvTrajectory again = lfd_dmp::readTrajectoryCsv(traj_csv);
    const lfd_dmp::CsvTrajectory demo = lfd_dmp::readTrajectoryCsv(csv);
    ASSERT_EQ(again.demo.positions.rows(), demo.demo.positions.rows());
    EXPECT_LT((again.demo.positions - demo.demo.positions).cwiseAbs().maxCoeff(), 1e-3) << basis;
    std::remove(json.c_str());
  }
  for (const auto& p : {csv, traj_csv}) std::remove(p.c_str());
}

TEST(DmpTool, GeneralizesAcrossDemosOfALibrary) {
  lfd_dmp::SkillLibrary lib;
  for (double gx : {0.5, 0.8}) {
    const std::string csv = writeDemoCsv("g.csv", gx);
    const std::string json = tempPath("g.json");
    ASSERT_EQ(run({"learn", "--csv", csv, "--out", json}), 0);
    lfd_dmp::SkillLibrary one = lfd_dmp::loadSkillLibrary(json);
    if (lib.segments.empty()) {
      lib = one;
    } else {
      lib.segments[0].demos.push_back(one.segments[0].demos[0]);
    }
    std::remove(csv.c_str());
    std::remove(json.c_str());
  }
  const std::string json = tempPath("two.json");
  const std::string traj_csv = tempPath("gen.csv");
  lfd_dmp::saveSkillLibrary(lib, json, false);
  std::string out, err;
  ASSERT_EQ(run({"rollout", "--library", json, "--out", traj_csv, "--generalize", "--goal",
                 "0.65,0.0,0.8", "--start", "0.3,0,0.8"},
                &out, &err),
            0)
      << err;
  EXPECT_EQ(out.find("warning"), std::string::npos) << out;
  const auto traj = lfd_dmp::readTrajectoryCsv(traj_csv);
  EXPECT_LT((traj.demo.positions.bottomRows(1).transpose() - Eigen::Vector3d(0.65, 0, 0.8)).norm(),
            2e-3);
  // The lift (0.1 m) is kept.
  EXPECT_NEAR(traj.demo.positions.col(2).maxCoeff(), 0.9, 0.01);
  // Far outside the demos: still rolls out but warns.
  ASSERT_EQ(run({"rollout", "--library", json, "--out", traj_csv, "--generalize", "--goal",
                 "1.5,0.4,0.8", "--overwrite"},
                &out, &err),
            0);
  EXPECT_NE(out.find("warning"), std::string::npos);
  for (const auto& p : {json, traj_csv}) std::remove(p.c_str());
}

TEST(DmpTool, BadInputGivesClearErrors) {
  std::string out, err;
  EXPECT_EQ(run({}, &out, &err), 2);
  EXPECT_EQ(run({"explode"}, &out, &err), 2);
  EXPECT_NE(err.find("unknown command"), std::string::npos);
  EXPECT_EQ(run({"learn", "--csv", "x.csv"}, &out, &err), 2);
  EXPECT_NE(err.find("missing --out"), std::string::npos);

  // NaN in a CSV row: line and column in the message, nothing written.
  const std::string csv = tempPath("nan.csv");
  const std::string json = tempPath("nan.json");
  {
    std::ofstream f(csv);
    f << "t,x,y\n0,0,0\n0.1,0.1,0\n0.2,nan,0\n";
  }
  EXPECT_EQ(run({"learn", "--csv", csv, "--out", json}, &out, &err), 1);
  EXPECT_NE(err.find("line 4, column 2 ('x')"), std::string::npos) << err;
  EXPECT_FALSE(std::ifstream(json).good());

  // Too short for a DMP.
  {
    std::ofstream f(csv);
    f << "t,x,y\n0,0,0\n0.1,0.1,0\n0.2,0.2,0\n";
  }
  EXPECT_EQ(run({"learn", "--csv", csv, "--out", json}, &out, &err), 1);
  EXPECT_NE(err.find("at least"), std::string::npos) << err;

  // Partial quaternion columns.
  {
    std::ofstream f(csv);
    f << "t,x,qw,qx\n0,0,1,0\n";
  }
  EXPECT_EQ(run({"learn", "--csv", csv, "--out", json}, &out, &err), 1);
  EXPECT_NE(err.find("qw,qx,qy,qz"), std::string::npos) << err;

  // Wrong goal dimension at rollout.
  const std::string good_csv = writeDemoCsv("ok.csv", 0.6, 100);
  ASSERT_EQ(run({"learn", "--csv", good_csv, "--out", json}), 0);
  EXPECT_EQ(
      run({"rollout", "--library", json, "--out", tempPath("o.csv"), "--goal", "1,2"}, &out, &err),
      2);
  EXPECT_NE(err.find("goal_position has 2 dims"), std::string::npos) << err;
  EXPECT_EQ(
      run({"rollout", "--library", json, "--out", tempPath("o.csv"), "--segment", "3"}, &out, &err),
      2);
  for (const auto& p : {csv, json, good_csv}) std::remove(p.c_str());
}

std::string fileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Regression: an existing output was silently replaced, even when it was the command's own input.
TEST(DmpTool, KeepsAnExistingOutputUnlessOverwrite) {
  const std::string csv = writeDemoCsv("keep.csv", 0.6, 100);
  const std::string json = tempPath("keep.json");
  { std::ofstream(json) << "precious\n"; }
  std::string out, err;
  EXPECT_EQ(run({"learn", "--csv", csv, "--out", json}, &out, &err), 1);
  EXPECT_NE(err.find("exists; set overwrite"), std::string::npos) << err;
  EXPECT_EQ(fileText(json), "precious\n");
  // Regression: --overwrite replaced any file; it replaces only a skill library lfd wrote.
  EXPECT_EQ(run({"learn", "--csv", csv, "--out", json, "--overwrite"}, &out, &err), 1);
  EXPECT_NE(err.find("keep.json"), std::string::npos) << err;
  EXPECT_NE(err.find("was not written by lfd as a skill library"), std::string::npos) << err;
  EXPECT_EQ(fileText(json), "precious\n");
  std::remove(json.c_str());
  ASSERT_EQ(run({"learn", "--csv", csv, "--out", json}, &out, &err), 0) << err;
  ASSERT_EQ(
      run({"learn", "--csv", csv, "--out", json, "--overwrite", "--task", "again"}, &out, &err), 0)
      << err;
  EXPECT_EQ(lfd_dmp::loadSkillLibrary(json).task, "again");
  for (const auto& p : {csv, json}) std::remove(p.c_str());
}

// Regression: a rollout's --overwrite replaces only a trajectory CSV dmp_tool wrote (its first line
// marks it); a demonstration CSV or any other file of that name is kept.
TEST(DmpTool, RolloutOverwritesOnlyATrajectoryItWrote) {
  const std::string csv = writeDemoCsv("roll.csv", 0.6, 100);
  const std::string json = tempPath("roll.json");
  const std::string traj = tempPath("roll_traj.csv");
  const std::string other = writeDemoCsv("roll_other.csv", 0.5, 50);  // a CSV lfd did not write
  const std::string before = fileText(other);
  std::string out, err;
  ASSERT_EQ(run({"learn", "--csv", csv, "--out", json}, &out, &err), 0) << err;
  EXPECT_EQ(run({"rollout", "--library", json, "--out", other, "--overwrite"}, &out, &err), 1);
  EXPECT_NE(err.find("was not written by lfd as a trajectory CSV"), std::string::npos) << err;
  EXPECT_EQ(fileText(other), before);
  ASSERT_EQ(run({"rollout", "--library", json, "--out", traj}, &out, &err), 0) << err;
  EXPECT_EQ(fileText(traj).rfind(std::string(lfd_dmp::kTrajectoryCsvMarker) + "\nt,x,y,z", 0), 0u);
  ASSERT_EQ(
      run({"rollout", "--library", json, "--out", traj, "--overwrite", "--tau", "3"}, &out, &err),
      0)
      << err;
  EXPECT_NEAR(lfd_dmp::readTrajectoryCsv(traj).demo.times.tail(1)(0), 3.0, 0.01);
  for (const auto& p : {csv, json, traj, other}) std::remove(p.c_str());
}

// Regression: a CSV saved with a UTF-8 byte-order mark named its first column "\xef\xbb\xbft";
// UTF-16 is refused saying so.
TEST(DmpTool, AUtf8ByteOrderMarkIsSkippedAndUtf16IsRefused) {
  const std::string plain = writeDemoCsv("bom_plain.csv", 0.6, 100);
  const std::string bom = tempPath("bom.csv");
  std::ofstream(bom, std::ios::binary) << "\xEF\xBB\xBF" << fileText(plain);
  const lfd_dmp::CsvTrajectory traj = lfd_dmp::readTrajectoryCsv(bom);
  EXPECT_EQ(traj.position_names, (std::vector<std::string>{"x", "y", "z"}));
  EXPECT_EQ(traj.demo.times.size(), 100);
  EXPECT_NEAR(traj.demo.times(99), 2.0, 1e-9);  // the time column is t, not column 0 by chance
  const std::string utf16 = tempPath("utf16.csv");
  {
    std::ofstream out(utf16, std::ios::binary);
    out << "\xFE\xFF";
    for (char c : std::string("t,x\n0,1\n")) out << '\0' << c;
  }
  try {
    lfd_dmp::readTrajectoryCsv(utf16);
    ADD_FAILURE() << "a UTF-16 CSV was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("UTF-16 is not supported, save it as UTF-8"),
              std::string::npos)
        << e.what();
  }
  for (const auto& p : {plain, bom, utf16}) std::remove(p.c_str());
}

// Regression: a library's strings are bounded when it is loaded (library_limits); one lfd writes
// must load again, so a 10 kB task name is refused before anything is written.
TEST(DmpTool, ALibraryThatCouldNotBeLoadedIsNeverWritten) {
  const std::string csv = writeDemoCsv("long_task.csv", 0.6, 100);
  const std::string json = tempPath("long_task.json");
  std::string out, err;
  EXPECT_EQ(
      run({"learn", "--csv", csv, "--out", json, "--task", std::string(10000, 't')}, &out, &err),
      1);
  EXPECT_NE(err.find("skill library.task: a string of 10000 is over the limit of 4096 "
                     "(library_limits/max_string_length)"),
            std::string::npos)
      << err.substr(0, 500);
  EXPECT_LT(err.size(), 500u);
  EXPECT_FALSE(std::ifstream(json).good());
  std::remove(csv.c_str());
}

TEST(DmpTool, NeverWritesOverItsInput) {
  const std::string csv = writeDemoCsv("self.csv", 0.6, 100);
  const std::string before = fileText(csv);
  std::string out, err;
  EXPECT_EQ(run({"learn", "--csv", csv, "--out", csv, "--overwrite"}, &out, &err), 1);
  EXPECT_NE(err.find("one of the request's inputs"), std::string::npos) << err;
  const std::string json = tempPath("self.json");
  ASSERT_EQ(run({"learn", "--csv", csv, "--out", json}), 0);
  const std::string library = fileText(json);
  EXPECT_EQ(run({"rollout", "--library", json, "--out", json, "--overwrite"}, &out, &err), 1);
  EXPECT_NE(err.find("one of the request's inputs"), std::string::npos) << err;
  EXPECT_EQ(fileText(csv), before);
  EXPECT_EQ(fileText(json), library);
  for (const auto& p : {csv, json}) std::remove(p.c_str());
}

// A named pipe as input blocked open() forever; it must be refused at once. Should the code under
// test block, the test opens the pipe's other end itself, so it fails instead of hanging.
int runGuarded(const std::vector<std::string>& args, const std::string& fifo, std::string* err) {
  auto done = std::async(std::launch::async, [&] { return run(args, nullptr, err); });
  if (done.wait_for(std::chrono::seconds(10)) == std::future_status::timeout) {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // releases a blocked reader
    if (fd >= 0) ::close(fd);
    ADD_FAILURE() << "blocked on the named pipe";
  }
  return done.get();
}

TEST(DmpTool, RefusesANamedPipeWithoutBlocking) {
  const std::string fifo = tempPath("pipe.csv");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string err;
  EXPECT_EQ(runGuarded({"learn", "--csv", fifo, "--out", tempPath("pipe.json")}, fifo, &err), 1);
  EXPECT_NE(err.find("named pipe"), std::string::npos) << err;
  EXPECT_EQ(runGuarded({"info", "--library", fifo}, fifo, &err), 1);
  EXPECT_NE(err.find("named pipe"), std::string::npos) << err;
  std::remove(fifo.c_str());
}

}  // namespace

// catkin_add_gtest links gtest without gtest_main (and the static gtest_main archive is then simply
// not pulled in by the standalone build).
int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
