// The `segment` CLI's CSV path (run as a subprocess, JSON parsed back), the feature matrices it
// emits for the figures, and the CSV reader.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <random>

#include <sys/stat.h>

#include "demo_bag_writer.hpp"
#include "lfd_segmentation/bag_features.hpp"
#include "lfd_segmentation/csv_features.hpp"
#include "lfd_segmentation/segmentation_json.hpp"

namespace {

namespace fs = std::filesystem;

fs::path tempDir() {
  const fs::path dir = fs::temp_directory_path() / ("lfd_cli_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

// A grasp-like CSV: time, gripper (step), speed (texture changes), noise, touch (sensor); one row
// every `step` seconds.
std::size_t writeDemoCsv(const std::string& path, int n, unsigned seed, double step = 0.02) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const std::size_t grasp = static_cast<std::size_t>(0.4 * n);
  std::ofstream out(path);
  out << "time,gripper,speed,noise,touch\n";
  for (int i = 0; i < n; ++i) {
    const double t = double(i) / (n - 1);
    const bool closed = i >= int(grasp);
    const double phase = closed ? (t - 0.4) / 0.6 : t / 0.4;
    out << step * i << "," << (closed ? 0.02 : 0.08) + 0.0005 * noise(rng) << ","
        << std::sin(M_PI * phase) * (closed ? 0.2 : 0.3) +
               0.05 * std::sin(2 * M_PI * i / (closed ? 9.0 : 23.0)) + 0.003 * noise(rng)
        << "," << noise(rng) << "," << (closed ? 4.0 : 0.0) + 0.02 * noise(rng) << "\n";
  }
  return grasp;
}

nlohmann::json runCli(const std::string& args, int* status, const std::string& prefix = "") {
  const std::string out = (tempDir() / "out.json").string();
  fs::remove(out);  // a run that writes nothing must not be judged by the previous JSON
  const std::string cmd =
      prefix + std::string(SEGMENT_CLI) + " " + args + " --output " + out + " 2>/dev/null";
  const int rc = std::system(cmd.c_str());
  *status = WEXITSTATUS(rc);
  std::ifstream in(out);
  return nlohmann::json::parse(in);
}

TEST(SegmentCli, SingleCsvRunsPlainMultivariateClasp) {
  const std::string csv = (tempDir() / "one.csv").string();
  const std::size_t grasp = writeDemoCsv(csv, 500, 1);
  int status = -1;
  const auto j = runCli("--state-columns gripper,speed " + csv, &status);
  ASSERT_EQ(status, 0) << j.dump();
  EXPECT_EQ(j["mode"], "clasp");
  ASSERT_EQ(j["demos"].size(), 1u);
  const auto& cps = j["demos"][0]["changepoints"];
  ASSERT_GE(cps.size(), 1u);
  bool near = false;
  // Tests the CLI plumbing; ClaSP places a step within about one window (50 samples) of it.
  for (const auto& cp : cps) near = near || std::abs(cp.get<double>() - double(grasp)) < 75;
  EXPECT_TRUE(near) << cps.dump();
  EXPECT_EQ(j["demos"][0]["profile"].size(), 500u);
  EXPECT_NEAR(j["demos"][0]["changepoint_times"][0].get<double>(), 0.02 * cps[0].get<double>(),
              1e-9);
}

TEST(SegmentCli, SeveralCsvRunThePipelineWithSensorValidation) {
  std::string files;
  std::vector<std::size_t> grasps;
  for (int d = 0; d < 3; ++d) {
    const std::string csv = (tempDir() / ("demo" + std::to_string(d) + ".csv")).string();
    grasps.push_back(writeDemoCsv(csv, 450 + 30 * d, 10 + d));
    files += " " + csv;
  }
  int status = -1;
  const auto j = runCli("--sensor-columns touch --timing" + files, &status);
  ASSERT_EQ(status, 0) << j.dump();
  EXPECT_EQ(j["mode"], "pipeline");
  EXPECT_TRUE(j["relevance_computed"].get<bool>());
  EXPECT_EQ(j["sensor_features"], nlohmann::json::array({"touch"}));
  ASSERT_EQ(j["relevance"]["features"].size(), 3u);  // gripper, speed, noise
  for (const auto& f : j["relevance"]["features"]) {
    EXPECT_EQ(f["correlation"].size(), 3u);
    if (f["name"] == "noise") {
      EXPECT_FALSE(f["selected"].get<bool>());
    }
  }
  ASSERT_EQ(j["demos"].size(), 3u);
  for (int d = 0; d < 3; ++d) {
    const auto& demo = j["demos"][d];
    ASSERT_EQ(demo["changepoints"].size(), 1u) << demo.dump();
    EXPECT_NEAR(demo["changepoints"][0].get<double>(), double(grasps[d]), 0.1 * (450 + 30 * d));
    EXPECT_FALSE(demo["zones"].empty());
  }
  EXPECT_TRUE(j.contains("timing"));
}

// Several combinations: one feature selection, one result per method under "methods", each the
// same as a run with that method alone; a name given twice or one CSV alone is an error.
TEST(SegmentCli, SeveralCombinationsShareOneSelection) {
  std::string files;
  for (int d = 0; d < 3; ++d) {
    const std::string csv = (tempDir() / ("multi" + std::to_string(d) + ".csv")).string();
    writeDemoCsv(csv, 450 + 30 * d, 20 + d);
    files += " " + csv;
  }
  int status = -1;
  const auto all =
      runCli("--sensor-columns touch --no-profiles --combination all" + files, &status);
  ASSERT_EQ(status, 0) << all.dump();
  ASSERT_EQ(all["methods"].size(), 6u);
  const auto two =
      runCli("--sensor-columns touch --no-profiles --combination product,weighted_average" + files,
             &status);
  ASSERT_EQ(status, 0) << two.dump();
  ASSERT_EQ(two["methods"].size(), 2u);
  const auto alone =
      runCli("--sensor-columns touch --no-profiles --combination product" + files, &status);
  ASSERT_EQ(status, 0);
  EXPECT_FALSE(alone.contains("methods"));
  for (int d = 0; d < 3; ++d) {
    EXPECT_EQ(two["methods"]["product"]["demos"][d]["changepoints"],
              alone["demos"][d]["changepoints"]);
    EXPECT_EQ(all["methods"]["product"]["demos"][d]["changepoints"],
              alone["demos"][d]["changepoints"]);
  }
  EXPECT_EQ(two["methods"]["product"]["selected_features"], alone["selected_features"]);
  auto bad = runCli("--sensor-columns touch --combination product,product" + files, &status);
  EXPECT_EQ(status, 1);
  EXPECT_NE(bad["error"].get<std::string>().find("twice"), std::string::npos) << bad.dump();
  bad = runCli("--combination product,average " + (tempDir() / "multi0.csv").string(), &status);
  EXPECT_EQ(status, 1);
  EXPECT_NE(bad["error"].get<std::string>().find("several combinations"), std::string::npos);
}

TEST(SegmentCli, BadInputFailsWithAnErrorInTheJson) {
  const std::string csv = (tempDir() / "bad.csv").string();
  std::ofstream(csv) << "time,a,b\n0,1,2\n0.1,nan,3\n0.2,1,4\n";
  int status = -1;
  auto j = runCli(csv + " " + csv + " --sensor-columns b", &status);
  EXPECT_EQ(status, 1);
  EXPECT_FALSE(j["success"].get<bool>());
  EXPECT_NE(j["error"].get<std::string>().find("'a' has NaN"), std::string::npos) << j.dump();
  j = runCli("/nonexistent.csv", &status);
  EXPECT_EQ(status, 1);
  EXPECT_NE(j["error"].get<std::string>().find("cannot open"), std::string::npos);
  j = runCli("--bogus x " + csv, &status);
  EXPECT_EQ(status, 1);
}

// Regression: a column name or a file name with bytes that are not UTF-8 made the JSON writer
// throw (nlohmann type_error 316) and the CLI abort (exit 134). Now the JSON is valid (U+FFFD for
// the bad bytes), an error quotes the name printably, and never more than ~200 characters of it.
TEST(SegmentCli, NonUtf8NamesGiveValidJsonAndLongInputIsQuotedShort) {
  const std::string csv = (tempDir() / "bad_header.csv").string();
  writeDemoCsv(csv, 300, 7);
  {  // the header's second column becomes "gr\xffipper"
    std::ifstream in(csv);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.replace(text.find("gripper"), 7, "gr\xff\xfeipper");
    std::ofstream(csv) << text;
  }
  int status = -1;
  auto j = runCli(csv, &status);
  ASSERT_EQ(status, 0) << j.dump();
  EXPECT_EQ(j["selected_features"][0].get<std::string>(), "gr\xef\xbf\xbd\xef\xbf\xbdipper")
      << j["selected_features"].dump();

  const std::string named = (tempDir() / "demo_\xff\xc3.csv").string();
  fs::copy_file(csv, named, fs::copy_options::overwrite_existing);
  j = runCli(named, &status);
  ASSERT_EQ(status, 0) << j.dump();
  EXPECT_NE(j["demos"][0]["source"].get<std::string>().find("demo_\xef\xbf\xbd"),
            std::string::npos);

  j = runCli((tempDir() / "missing_\xff.csv").string(), &status);
  EXPECT_EQ(status, 1);
  EXPECT_NE(j["error"].get<std::string>().find("missing_\\xff.csv"), std::string::npos) << j.dump();

  const std::string long_name = "/nonexistent/" + std::string(5000, 'a') + ".csv";
  j = runCli(long_name, &status);
  EXPECT_EQ(status, 1);
  EXPECT_LT(j["error"].get<std::string>().size(), 400u) << j["error"].get<std::string>().size();
  EXPECT_NE(j["error"].get<std::string>().find("(5017 bytes)"), std::string::npos);
}

// Each feature's role as the bag reader gave it.
std::map<std::string, std::string> rolesOf(const lfd_segmentation::DemoFeatures& demo) {
  std::map<std::string, std::string> roles;
  for (const std::string& name : demo.state_features) roles[name] = "state";
  for (const std::string& name : demo.sensor_features) roles[name] = "sensor";
  for (const std::string& name : demo.context_features) roles[name] = "context";
  return roles;
}

// `segment --features` emits the matrix the segmentation read, which the figures draw: the bag
// reader's resampling of the same config, exactly its clock (that of the changepoint times),
// every feature with its role and each value within half its rounding step, in few bytes.
// A wrist F/T logs at 1 kHz: 13 s demos are 13,000 rows, over the per-demo sample limit. They
// are averaged onto the fastest whole-Hz clock that fits (923 Hz), with a warning saying so, and
// --resample 50 chooses a 50 Hz clock: the same grasps are found (within 0.1 s of the step at 40 %
// of each demo) as in the same demos logged at 50 Hz.
TEST(SegmentCli, ResampleAveragesAFastCsvOntoASlowerClock) {
  std::string fast, slow;
  for (unsigned d = 0; d < 3; ++d) {
    const std::string f = (tempDir() / ("fast" + std::to_string(d) + ".csv")).string();
    const std::string g = (tempDir() / ("slow" + std::to_string(d) + ".csv")).string();
    writeDemoCsv(f, 13000, 40 + d, 0.001);
    writeDemoCsv(g, 650, 40 + d, 0.02);
    fast += " " + f;
    slow += " " + g;
  }
  int status = 0;
  auto j = runCli("--sensor-columns touch" + fast, &status);
  ASSERT_EQ(status, 0) << j.dump();
  EXPECT_NE(j["warnings"].dump().find("averaged onto a 923 Hz clock"), std::string::npos)
      << j["warnings"];
  for (std::size_t d = 0; d < 3; ++d) {
    EXPECT_NEAR(j["demos"][d]["sample_rate"].get<double>(), 923.0, 1e-6);
    ASSERT_EQ(j["demos"][d]["changepoint_times"].size(), 1u) << j["demos"][d];
    EXPECT_NEAR(j["demos"][d]["changepoint_times"][0].get<double>(), 0.4 * 13.0, 0.1);
  }
  const auto fast_json = runCli("--sensor-columns touch --resample 50" + fast, &status);
  ASSERT_EQ(status, 0) << fast_json.dump();
  const auto slow_json = runCli("--sensor-columns touch" + slow, &status);
  ASSERT_EQ(status, 0) << slow_json.dump();
  for (std::size_t d = 0; d < 3; ++d) {
    const auto& a = fast_json["demos"][d];
    EXPECT_NEAR(a["sample_rate"].get<double>(), 50.0, 1e-6);
    ASSERT_EQ(a["changepoint_times"].size(), 1u) << a["changepoint_times"];
    ASSERT_EQ(slow_json["demos"][d]["changepoint_times"].size(), 1u);
    EXPECT_NEAR(a["changepoint_times"][0].get<double>(), 0.4 * 13.0, 0.1);
    EXPECT_NEAR(a["changepoint_times"][0].get<double>(),
                slow_json["demos"][d]["changepoint_times"][0].get<double>(), 0.1);
  }
  j = runCli("--resample 0 --sensor-columns touch" + fast, &status);
  EXPECT_EQ(status, 1);
  EXPECT_NE(j["error"].get<std::string>().find("--resample"), std::string::npos);
  // A time column in milliseconds read as seconds: 13,000 s at 50 Hz is refused before anything
  // is allocated.
  const std::string ms = (tempDir() / "milliseconds.csv").string();
  writeDemoCsv(ms, 13000, 7, 1.0);
  j = runCli("--sensor-columns touch --resample 50 " + ms + fast, &status);
  EXPECT_EQ(status, 1);
  EXPECT_NE(j["error"].get<std::string>().find("max_samples_per_demo"), std::string::npos)
      << j["error"];
}

// A logger that stalled for a second: the rows across the gap are not evenly spaced, which the
// segmentation assumes (its windows are counted in samples). The result says so, and the same demos
// put on a uniform clock (--resample) carry no such warning.
TEST(SegmentCli, AClockWithAGapIsWarnedAbout) {
  std::string files;
  for (unsigned d = 0; d < 3; ++d) {
    const std::string f = (tempDir() / ("gap" + std::to_string(d) + ".csv")).string();
    writeDemoCsv(f, 650, 60 + d);
    if (d == 0) {  // one second missing after row 300
      std::ifstream in(f);
      std::vector<std::string> lines;
      for (std::string line; std::getline(in, line);) lines.push_back(line);
      std::ofstream out(f);
      for (std::size_t r = 0; r < lines.size(); ++r) {
        if (r <= 300) {
          out << lines[r] << "\n";
          continue;
        }
        const std::size_t comma = lines[r].find(',');
        out << std::stod(lines[r].substr(0, comma)) + 1.0 << lines[r].substr(comma) << "\n";
      }
    }
    files += " " + f;
  }
  const auto warned = [](const nlohmann::json& j) {
    for (const auto& w : j["warnings"])
      if (w.get<std::string>().find("clock jumps") != std::string::npos) return true;
    return false;
  };
  int status = 0;
  const auto j = runCli("--sensor-columns touch" + files, &status);
  ASSERT_EQ(status, 0) << j.dump();
  EXPECT_TRUE(warned(j)) << j["warnings"];
  const auto uniform = runCli("--sensor-columns touch --resample 50" + files, &status);
  ASSERT_EQ(status, 0) << uniform.dump();
  EXPECT_FALSE(warned(uniform)) << uniform["warnings"];
}

TEST(SegmentCli, FeaturesAreTheMatrixTheBagReaderGave) {
  std::vector<std::string> bags;
  std::string files;
  for (unsigned d = 0; d < 3; ++d) {
    lfd_segmentation_test::DemoBagOptions o;
    o.seed = 40 + d;
    o.duration = 7.0 + 0.5 * d;
    bags.push_back((tempDir() / ("features" + std::to_string(d) + ".bag")).string());
    lfd_segmentation_test::writeDemoBag(bags.back(), o);
    files += " " + bags.back();
  }
  int status = -1;
  const auto j = runCli("--features --no-profiles" + files, &status);
  ASSERT_EQ(status, 0) << j.dump();
  const auto params =
      lfd_segmentation::loadParamsFile(std::string(LFD_CONFIG_DIR) + "/segmentation.yaml");
  ASSERT_EQ(j["feature_matrices"].size(), bags.size());
  for (std::size_t d = 0; d < bags.size(); ++d) {
    const lfd_segmentation::DemoFeatures read =
        lfd_segmentation::readBagFeatures(bags[d], params.topics, params.rate, params.limits);
    const nlohmann::json& m = j["feature_matrices"][d];
    EXPECT_EQ(m["time"].get<std::vector<double>>(), read.matrix.time);
    for (std::size_t k = 0; k < j["demos"][d]["changepoints"].size(); ++k) {
      EXPECT_EQ(m["time"][j["demos"][d]["changepoints"][k].get<std::size_t>()],
                j["demos"][d]["changepoint_times"][k]);
    }
    ASSERT_EQ(m["features"].size(), static_cast<std::size_t>(read.matrix.cols()));
    std::size_t values = 0;
    for (Eigen::Index c = 0; c < read.matrix.cols(); ++c) {
      const nlohmann::json& f = m["features"][c];
      const std::string name = read.matrix.names[c];
      EXPECT_EQ(f["name"], name);
      EXPECT_EQ(f["role"], rolesOf(read)[name]) << name;
      const std::vector<double> got = f["values"].get<std::vector<double>>();
      const Eigen::VectorXd want = read.matrix.data.col(c);
      ASSERT_EQ(got.size(), static_cast<std::size_t>(want.size())) << name;
      double error = 0;
      for (Eigen::Index r = 0; r < want.size(); ++r)
        error = std::max(error, std::abs(got[r] - want[r]));
      // Constant features here are 0 or 1, which any step keeps exactly.
      const double step =
          lfd_segmentation::kFeatureResolution * (want.maxCoeff() - want.minCoeff());
      EXPECT_LE(error, 0.5 * step * (1 + 1e-9)) << name;
      values += got.size();
    }
    // Rounded, not 17 digits: the 9 demos x 25 features x 600 samples of a dataset in ~1.5 MB.
    EXPECT_LT(double(m["features"].dump().size()) / values, 12.0);
  }
}

TEST(CsvFeatures, ParsesHeaderTimeAndRejectsRaggedRows) {
  const std::string csv = (tempDir() / "parse.csv").string();
  std::ofstream(csv) << "a, t ,b\n1,0.0,2\n3,0.5,4\n\n";
  const auto m = lfd_segmentation::readCsvFeatures(csv);
  EXPECT_EQ(m.names, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(m.rows(), 2);
  EXPECT_EQ(m.time, (std::vector<double>{0.0, 0.5}));
  EXPECT_EQ(m.data(1, 0), 3.0);
  EXPECT_EQ(m.data(1, 1), 4.0);
  const auto no_time = lfd_segmentation::readCsvFeatures(csv, "b", 0.0);
  EXPECT_EQ(no_time.names, (std::vector<std::string>{"a", "t"}));
  std::ofstream(csv) << "a,b\n1,2\n3\n";
  EXPECT_THROW(lfd_segmentation::readCsvFeatures(csv), std::invalid_argument);
  std::ofstream(csv) << "a,b\n1,x\n";
  EXPECT_THROW(lfd_segmentation::readCsvFeatures(csv), std::invalid_argument);
  std::ofstream(csv) << "a,b\n1,2\n";
  EXPECT_THROW(lfd_segmentation::readCsvFeatures(csv, "time"), std::invalid_argument);
  const auto rated = lfd_segmentation::readCsvFeatures(csv, "", 10.0);
  EXPECT_EQ(rated.time, (std::vector<double>{0.0}));
}

// Regression: a 10M-row CSV took 1.9 GB and no result in 300 s; +-1e308 overflowed the distances.
TEST(CsvFeatures, LimitsStopTheReadAndNameRowAndColumn) {
  const std::string csv = (tempDir() / "limits.csv").string();
  {
    std::ofstream out(csv);
    out << "time,a,b\n";
    for (int i = 0; i < 50; ++i) out << 0.02 * i << "," << i << ",1\n";
  }
  lfd_segmentation::RequestLimits limits;
  limits.max_csv_rows = 10;
  try {
    lfd_segmentation::readCsvFeatures(csv, "", 0.0, limits);
    ADD_FAILURE() << "50 rows read under a 10-row limit";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("limits/max_csv_rows"), std::string::npos) << e.what();
  }
  std::ofstream(csv) << "time,a,b\n0,1,2\n0.1,1,-1e308\n0.2,1,4\n";
  try {
    lfd_segmentation::readCsvFeatures(csv);
    ADD_FAILURE() << "-1e308 accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("line 3, column 3 ('b')"), std::string::npos) << what;
    EXPECT_NE(what.find("limits/max_abs_value"), std::string::npos) << what;
  }
}

// Regression: a CSV saved with a UTF-8 byte-order mark (as spreadsheet programs save it) gave "no
// time column": the first column was named "\xef\xbb\xbftime". The mark is skipped; UTF-16 is
// refused saying so.
TEST(CsvFeatures, AUtf8ByteOrderMarkIsSkippedAndUtf16IsRefused) {
  const fs::path dir = tempDir();
  const std::string plain = (dir / "plain_bom.csv").string();
  writeDemoCsv(plain, 300, 4);
  std::ifstream plain_in(plain);
  const std::string text((std::istreambuf_iterator<char>(plain_in)), {});
  const std::string bom = (dir / "bom.csv").string();
  std::ofstream(bom, std::ios::binary) << "\xEF\xBB\xBF" << text;
  const lfd::FeatureMatrix m = lfd_segmentation::readCsvFeatures(bom);
  EXPECT_EQ(m.names, (std::vector<std::string>{"gripper", "speed", "noise", "touch"}));
  EXPECT_EQ(m.time.size(), 300u);
  int status = -1;
  const auto j = runCli("--state-columns gripper,speed " + bom, &status);
  EXPECT_EQ(status, 0) << j.dump();

  const std::string utf16 = (dir / "utf16.csv").string();
  {
    std::ofstream out(utf16, std::ios::binary);
    out << "\xFF\xFE";
    for (char c : std::string("time,a\n0,1\n")) out << c << '\0';
  }
  try {
    lfd_segmentation::readCsvFeatures(utf16);
    ADD_FAILURE() << "a UTF-16 CSV was read";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("utf16.csv"), std::string::npos) << what;
    EXPECT_NE(what.find("UTF-16 is not supported, save it as UTF-8"), std::string::npos) << what;
  }
}

// Regression: 10,000 feature columns took 1.1 GB. The header is checked against
// limits/max_features before any row is read.
TEST(CsvFeatures, TooManyFeatureColumnsAreRefusedOnTheHeader) {
  const std::string csv = (tempDir() / "wide.csv").string();
  {
    std::ofstream out(csv);
    out << "time";
    for (int c = 0; c < 300; ++c) out << ",f" << c;
    out << "\n";
    for (int r = 0; r < 5; ++r) {
      out << 0.01 * r;
      for (int c = 0; c < 300; ++c) out << "," << r + c;
      out << "\n";
    }
  }
  lfd_segmentation::RequestLimits limits;
  ASSERT_EQ(limits.max_features, 256u);
  try {
    lfd_segmentation::readCsvFeatures(csv, "", 0.0, limits);
    ADD_FAILURE() << "300 feature columns read under a limit of 256";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("300 feature columns, over the limit of 256 "
                                         "(limits/max_features)"),
              std::string::npos)
        << e.what();
  }
  int status = -1;
  const auto j = runCli(csv, &status);  // the CLI, with the shipped config
  EXPECT_EQ(status, 1);
  EXPECT_NE(j["error"].get<std::string>().find("limits/max_features"), std::string::npos)
      << j.dump();
}

// Regression: an output replaced any regular file. --output replaces a result file the CLI wrote
// (scripts rerun into their folder), never another file: it is kept and the error says why.
TEST(SegmentCli, OutputReplacesOnlyAResultFileItWrote) {
  const fs::path dir = tempDir();
  const std::string csv = (dir / "output_demo.csv").string();
  writeDemoCsv(csv, 300, 6);
  const std::string bashrc = (dir / ".bashrc").string();
  std::ofstream(bashrc) << "export PATH=$HOME/bin:$PATH\n";
  const std::string err = (dir / "stderr.txt").string();
  const std::string cmd =
      std::string(SEGMENT_CLI) + " " + csv + " --output " + bashrc + " 2>" + err;
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 1);
  std::ifstream kept(bashrc);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(kept)), {}),
            "export PATH=$HOME/bin:$PATH\n");
  std::ifstream err_in(err);
  const std::string message((std::istreambuf_iterator<char>(err_in)), {});
  EXPECT_NE(message.find(".bashrc"), std::string::npos) << message;
  EXPECT_NE(message.find("was not written by lfd"), std::string::npos) << message;
  // Its own result is replaced, run after run (also one written before the format marker).
  int status = -1;
  auto j = runCli(csv, &status);
  EXPECT_EQ(status, 0);
  EXPECT_EQ(j["format"], "lfd_segmentation_result");
  const std::string out = (dir / "result.json").string();
  std::ofstream(out) << R"({"mode": "clasp", "success": true})";
  const std::string again =
      std::string(SEGMENT_CLI) + " " + csv + " --output " + out + " 2>/dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(again.c_str())), 0);
  EXPECT_EQ(WEXITSTATUS(std::system(again.c_str())), 0);
  std::ifstream result(out);
  EXPECT_EQ(nlohmann::json::parse(result)["format"], "lfd_segmentation_result");
}

TEST(SegmentCli, RefusesAPipeAndNeverWritesOverAnInput) {
  const fs::path dir = tempDir();
  const std::string fifo = (dir / "pipe.csv").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  int status = -1;
  // `timeout` turns a hang on the old code into a failure instead of a stuck test.
  auto j = runCli(fifo, &status, "timeout 20 ");
  EXPECT_EQ(status, 1);
  EXPECT_NE(j["error"].get<std::string>().find("named pipe"), std::string::npos) << j.dump();
  fs::remove(fifo);
  const std::string csv = (dir / "input.csv").string();
  writeDemoCsv(csv, 300, 3);
  std::ifstream before_in(csv);
  const std::string before((std::istreambuf_iterator<char>(before_in)), {});
  const std::string cmd =
      std::string(SEGMENT_CLI) + " " + csv + " --output " + csv + " 2>/dev/null";
  EXPECT_NE(std::system(cmd.c_str()), 0);
  std::ifstream after_in(csv);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(after_in)), {}), before);
  // Durations no demo can have, and a window longer than the demo (6 s), are errors.
  for (const std::string bad : {"--min-segment-seconds inf", "--min-segment-seconds 1e300",
                                "--window-seconds 1e300", "--window-seconds 60"}) {
    j = runCli(csv + " " + bad, &status);
    EXPECT_EQ(status, 1) << bad;
    EXPECT_FALSE(j["success"].get<bool>()) << bad;
  }
}

// Property test of the CLI: 40 seeded random command lines of extreme values and bad
// files. Each run ends (under `timeout`) with exit 0 and a result or exit 1 and an error in the
// JSON, never a crash, and the input CSV keeps its bytes. About 2 s.
TEST(SegmentCli, RandomExtremeCommandLinesGiveAResultOrAClearError) {
  const fs::path dir = tempDir() / "fuzz";
  fs::create_directories(dir);
  const std::string csv = (dir / "demo.csv").string();
  writeDemoCsv(csv, 400, 5);
  const std::string fifo = (dir / "pipe.csv").string();
  ::mkfifo(fifo.c_str(), 0600);
  std::ifstream before_in(csv);
  const std::string before((std::istreambuf_iterator<char>(before_in)), {});
  const std::vector<std::string> files = {
      csv, csv, fifo, dir.string(), "/dev/null", (dir / "missing.csv").string(), "''"};
  const std::vector<std::string> flags = {
      "--rate",           "--threshold",        "--min-segment-seconds",
      "--window-seconds", "--num-changepoints", "--threads"};
  const std::vector<std::string> values = {"0",      "-1",  "0.5", "2",           "1e300", "-1e300",
                                           "1e-300", "inf", "nan", "99999999999", "x",     "''"};
  std::mt19937 rng(12);
  for (int k = 0; k < 40; ++k) {
    std::string args;
    const int n_files = 1 + static_cast<int>(rng() % 3);
    for (int f = 0; f < n_files; ++f) args += " " + files[rng() % files.size()];
    for (int f = static_cast<int>(rng() % 3); f > 0; --f)
      args += " " + flags[rng() % flags.size()] + " " + values[rng() % values.size()];
    if (rng() % 3 == 0) args += " --sensor-columns touch";
    int status = -1;
    nlohmann::json j;
    try {
      j = runCli(args, &status, "timeout 20 ");
    } catch (const std::exception& e) {
      ADD_FAILURE() << args << ": no JSON (" << e.what() << ")";
      continue;
    }
    EXPECT_TRUE(status == 0 || status == 1) << args << " exit " << status;
    EXPECT_EQ(j["success"].get<bool>(), status == 0) << args;
    if (status != 0) {
      EXPECT_FALSE(j["error"].get<std::string>().empty()) << args;
    }
    std::ifstream after_in(csv);
    ASSERT_EQ(std::string((std::istreambuf_iterator<char>(after_in)), {}), before) << args;
  }
  fs::remove_all(dir);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
