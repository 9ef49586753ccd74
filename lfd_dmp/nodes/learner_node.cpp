// learner_node: service /learner/learn (lfd_msgs/LearnSkills). Reads the demonstration bags, cuts
// them at the validated changepoints, learns one DMP set per segment per demo and each segment's
// goal frame from the demos' scenes, and writes the skill library. Thin adapter over
// lfd_dmp::learnSkillLibrary / readDemoBag.
// Private parameters (config/learner.yaml): ~pose_topic, ~gripper_topic, ~gripper_joint,
// ~num_basis, ~smoothing_sigma, ~time_alignment/*, ~goal_frames/*, ~allowed_roots,
// ~limits/{max_bags, max_total_bytes, max_num_basis, max_demo_seconds, max_samples_per_demo,
// max_request_string_bytes}.
// Paths: absolute, bags must be regular files inside the roots, the library is written atomically,
// never over a bag, and over an existing file only with overwrite and only when that file is a
// skill library lfd wrote.
#include "lfd_dmp/demo_bag.hpp"
#include "lfd_dmp/demo_sensors.hpp"
#include "lfd_dmp/skill_learner.hpp"

#include <lfd_msgs/LearnSkills.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <lfd_core/io/input_budget.hpp>
#include <lfd_core/io/safe_paths.hpp>
#include <lfd_core/segmentation/time_alignment.hpp>
#include <lfd_core/util/heap_trim.hpp>
#include <lfd_ros/master_watch.hpp>
#include <lfd_ros/ros_request_strings.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace {

class Learner {
 public:
  explicit Learner(ros::NodeHandle& pnh) : tf_listener_(tf_buffer_) {
    pnh.param<std::string>("pose_topic", topics_.pose, topics_.pose);
    pnh.param<std::string>("gripper_topic", topics_.gripper, topics_.gripper);
    pnh.param<std::string>("gripper_joint", topics_.gripper_joint, topics_.gripper_joint);
    pnh.param<int>("num_basis", num_basis_, num_basis_);
    pnh.param<double>("smoothing_sigma", smoothing_sigma_, smoothing_sigma_);
    if (!(smoothing_sigma_ >= 0.0)) {
      ROS_WARN("learner: ~smoothing_sigma %.3f < 0: smoothing off", smoothing_sigma_);
      smoothing_sigma_ = 0.0;
    }
    readTimeAlignment(pnh);
    pnh.param("allowed_roots", paths_.allowed_roots, paths_.allowed_roots);
    paths_.require_absolute = true;  // the node's working directory is not the caller's
    int max_string = static_cast<int>(strings_.max_bytes);
    pnh.param("limits/max_request_string_bytes", max_string, max_string);
    strings_.max_bytes = static_cast<std::size_t>(std::max(max_string, 0));
    strings_.key = "~limits/max_request_string_bytes";
    pnh.param("limits/max_bags", max_bags_, max_bags_);
    pnh.param("limits/max_total_bytes", max_total_bytes_, max_total_bytes_);
    pnh.param("limits/max_num_basis", max_num_basis_, max_num_basis_);
    pnh.param("limits/max_demo_seconds", max_demo_seconds_, max_demo_seconds_);
    pnh.param("limits/max_samples_per_demo", max_samples_per_demo_, max_samples_per_demo_);
    pnh.param("goal_frames/min_heading_length", frames_.frames.min_heading_length,
              frames_.frames.min_heading_length);
    pnh.param("goal_frames/heading_tolerance", frames_.heading_tolerance,
              frames_.heading_tolerance);
    pnh.param("goal_frames/min_motion_length", frames_.min_motion_length,
              frames_.min_motion_length);
    pnh.param("goal_frames/tie_z", frames_.tie_z, frames_.tie_z);
    if (!(frames_.tie_z >= 0.0) || !std::isfinite(frames_.tie_z))
      throw std::runtime_error("learner: ~goal_frames/tie_z must be finite and >= 0");
    pnh.param("tf_timeout", tf_timeout_, tf_timeout_);
    readSignature(pnh);
  }

  bool learn(lfd_msgs::LearnSkills::Request& req, lfd_msgs::LearnSkills::Response& res) {
    const lfd::TrimHeapOnExit trim;  // the demos read go back to the system once answered
    const auto t0 = std::chrono::steady_clock::now();
    try {
      lfd::checkRequestStrings(req, strings_);  // before any work: no 10 MB string echoed
      if (req.output_path.empty()) throw std::invalid_argument("output_path is empty");
      lfd::checkRequestPath("output_path", req.output_path, paths_);
      checkCounts(req);
      std::vector<std::string> bags;
      std::vector<std::vector<double>> cps;
      requestedDemos(req, &bags, &cps);
      if (bags.empty()) throw std::invalid_argument("no demonstrations given");
      checkBudget(bags);
      const std::string output = lfd::checkOutputFile(req.output_path, paths_, req.overwrite, bags,
                                                      lfd_dmp::skillLibraryOutput());
      const std::vector<lfd_dmp::DemoRecording> demos = readDemos(bags);
      std::vector<std::string> read_warnings;  // stamps the readers put in order, per demo
      for (const auto& d : demos)
        read_warnings.insert(read_warnings.end(), d.warnings.begin(), d.warnings.end());
      const lfd_dmp::LearnOutcome out = lfd_dmp::learnSkillLibrary(demos, cps, learnOptions(req));
      lfd_dmp::saveSkillLibrary(out.library, output, req.overwrite);
      res.success = true;
      res.warnings = read_warnings;
      res.warnings.insert(res.warnings.end(), out.warnings.begin(), out.warnings.end());
      res.library_path = output;
      res.num_segments = static_cast<uint32_t>(out.library.segments.size());
      res.num_demos = static_cast<uint32_t>(out.demos_used);
      for (const auto& w : res.warnings) ROS_WARN("learner: %s", w.c_str());
      ROS_INFO("learner: %u segments x %u demos -> %s", res.num_segments, res.num_demos,
               req.output_path.c_str());
    } catch (const std::exception& e) {
      res.success = false;
      res.error = e.what();
      ROS_ERROR("learner: %s", e.what());
    }
    res.elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return true;  // failures are reported in the response, not as a transport error
  }

 private:
  // The request's bags (paths checked) and each one's changepoint times: from its segmentations,
  // else from bag_paths with changepoint_counts splitting changepoint_times.
  void requestedDemos(const lfd_msgs::LearnSkills::Request& req, std::vector<std::string>* bags,
                      std::vector<std::vector<double>>* cps) const {
    if (!req.segmentations.empty()) {
      for (size_t i = 0; i < req.segmentations.size(); ++i) {
        const auto& s = req.segmentations[i];
        lfd::checkRequestPath("segmentations[" + std::to_string(i) + "].source", s.source, paths_);
        bags->push_back(s.source);
        cps->push_back(s.changepoint_times);
      }
      return;
    }
    if (req.changepoint_counts.size() != req.bag_paths.size()) {
      throw std::invalid_argument("changepoint_counts needs one entry per bag");
    }
    size_t k = 0;
    for (size_t i = 0; i < req.bag_paths.size(); ++i) {
      lfd::checkRequestPath("bag_paths[" + std::to_string(i) + "]", req.bag_paths[i], paths_);
      bags->push_back(req.bag_paths[i]);
      std::vector<double> c;
      for (uint32_t j = 0; j < req.changepoint_counts[i]; ++j) {
        if (k >= req.changepoint_times.size()) {
          throw std::invalid_argument("changepoint_times has fewer entries than the counts");
        }
        c.push_back(req.changepoint_times[k++]);
      }
      cps->push_back(c);
    }
    if (k != req.changepoint_times.size()) {
      throw std::invalid_argument("changepoint_times has more entries than the counts");
    }
  }

  // Each bag's poses (a bag without /tf_static: live tf), size-checked, and its sensors when a
  // signature is learned.
  std::vector<lfd_dmp::DemoRecording> readDemos(const std::vector<std::string>& bags) {
    std::vector<lfd_dmp::DemoRecording> demos;
    for (const auto& b : bags) {
      demos.push_back(lfd_dmp::readDemoBag(
          b, topics_, [this](const std::string& target, const std::string& source) {
            return liveTransform(target, source);
          }));
      checkDemoSize(demos.back(), b);
      if (signature_) lfd_dmp::readDemoSensors(b, sensors_, &demos.back());
    }
    return demos;
  }

  lfd_dmp::LearnOptions learnOptions(const lfd_msgs::LearnSkills::Request& req) const {
    lfd_dmp::LearnOptions opt;
    opt.task = req.task;
    opt.features = req.selected_features;
    opt.segment_names = req.segment_names;
    opt.params.num_basis = req.num_basis > 0 ? req.num_basis : num_basis_;
    opt.smoothing_sigma = smoothing_sigma_;
    opt.time_alignment = time_alignment_;
    opt.frames = frames_;
    opt.signature = signature_;
    return opt;
  }

  // The request's work, checked before any bag is read: its bags and their total size (each one
  // opened by the file-access layer: a regular file inside the roots).
  void checkBudget(const std::vector<std::string>& bags) const {
    lfd::InputBudget budget;
    budget.what = "bags";
    budget.max_files = static_cast<std::size_t>(std::max(max_bags_, 0));
    budget.max_files_key = "~limits/max_bags";
    budget.max_total_bytes = static_cast<std::uint64_t>(std::max(max_total_bytes_, 0.0));
    budget.max_total_bytes_key = "~limits/max_total_bytes";
    lfd::checkInputBudget(bags, budget, paths_);
  }

  // A bag without /tf_static (recorded before it was): the live tf tree (e.g. the robot model's
  // fixed world -> base_link from robot_state_publisher), waited for in WALL time.
  Eigen::Isometry3d liveTransform(const std::string& target, const std::string& source) {
    std::string why;
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(tf_timeout_);
    while (why.clear(), !tf_buffer_.canTransform(target, source, ros::Time(0), &why)) {
      if (ros::WallTime::now() > deadline || !ros::ok())
        throw std::runtime_error("no transform from '" + source + "' to '" + target + "' (" + why +
                                 ")");
      ros::WallDuration(0.01).sleep();
    }
    const auto t = tf_buffer_.lookupTransform(target, source, ros::Time(0)).transform;
    Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
    iso.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
    iso.linear() = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z)
                       .normalized()
                       .toRotationMatrix();
    return iso;
  }

  void checkCounts(const lfd_msgs::LearnSkills::Request& req) const {
    if (req.num_basis > max_num_basis_) {
      throw std::invalid_argument("num_basis " + std::to_string(req.num_basis) +
                                  " is over the limit of " + std::to_string(max_num_basis_) +
                                  " (~limits/max_num_basis)");
    }
  }

  // One message stamped hours late would make a demo hours long (and its DMP meaningless).
  void checkDemoSize(const lfd_dmp::DemoRecording& demo, const std::string& bag) const {
    const auto n = demo.times.size();
    const double span = n ? demo.times[n - 1] - demo.times[0] : 0.0;
    if (span > max_demo_seconds_) {
      throw std::invalid_argument(bag + ": poses span " + std::to_string(span) +
                                  " s, over the limit of " + std::to_string(max_demo_seconds_) +
                                  " s (~limits/max_demo_seconds)");
    }
    if (static_cast<double>(n) > max_samples_per_demo_) {
      throw std::invalid_argument(bag + ": " + std::to_string(n) + " poses, over the limit of " +
                                  std::to_string(max_samples_per_demo_) +
                                  " (~limits/max_samples_per_demo)");
    }
  }

  // ~time_alignment/{enabled, sample_seconds, warp_sigma}; a bad value turns it off, loudly.
  void readTimeAlignment(ros::NodeHandle& pnh) {
    bool enabled = false;
    pnh.param("time_alignment/enabled", enabled, enabled);
    if (!enabled) return;
    lfd::TimeAlignmentOptions a;
    pnh.param("time_alignment/sample_seconds", a.sample_seconds, a.sample_seconds);
    pnh.param("time_alignment/warp_sigma", a.warp_sigma, a.warp_sigma);
    try {
      lfd::checkTimeAlignmentOptions(a, "~time_alignment/");
    } catch (const std::invalid_argument& e) {
      ROS_WARN("learner: %s: alignment off", e.what());
      return;
    }
    time_alignment_ = a;
  }

  // ~signature/{enabled, topics_file, phase_bins, ...}: what each segment's sensors showed; a bad
  // value turns it off, loudly (the library is still learned, its reproductions not monitored).
  void readSignature(ros::NodeHandle& pnh) {
    bool enabled = false;
    std::string file;
    pnh.param("signature/enabled", enabled, enabled);
    pnh.param("signature/topics_file", file, file);
    if (!enabled) return;
    lfd::SignatureOptions o;
    int bins = static_cast<int>(o.phase_bins);
    pnh.param("signature/phase_bins", bins, bins);
    o.phase_bins = static_cast<std::size_t>(std::max(bins, 0));
    pnh.param("signature/phase_slack", o.phase_slack, o.phase_slack);
    pnh.param("signature/time_slack_seconds", o.time_slack, o.time_slack);
    pnh.param("signature/persistence_seconds", o.persistence, o.persistence);
    pnh.param("signature/min_spread_fraction", o.min_spread_fraction, o.min_spread_fraction);
    pnh.param("signature/noise_sigmas", o.noise_sigmas, o.noise_sigmas);
    pnh.param("signature/threshold_margin", o.threshold_margin, o.threshold_margin);
    pnh.param("signature/min_threshold", o.min_threshold, o.min_threshold);
    pnh.param("signature/rest_band_fraction", o.rest_band_fraction, o.rest_band_fraction);
    try {
      lfd::checkSignatureOptions(o);
      sensors_ = lfd_dmp::loadMonitoredSensors(file);
    } catch (const std::exception& e) {
      ROS_WARN("learner: ~signature: %s: no sensory signatures", e.what());
      return;
    }
    signature_ = o;
    ROS_INFO("learner: sensory signatures from %zu monitored topic(s) of %s",
             sensors_.topics.size(), file.c_str());
  }

  lfd_dmp::DemoBagTopics topics_;
  std::optional<lfd::SignatureOptions> signature_;
  lfd_dmp::MonitoredSensors sensors_;
  lfd::PathPolicy paths_;
  lfd::StringBudget strings_;
  int max_bags_ = 64;
  double max_total_bytes_ = 1e9;  // a double: ROS int parameters stop at 2^31
  int max_num_basis_ = 1000;
  double max_demo_seconds_ = 120.0;
  int max_samples_per_demo_ = 30000;
  int num_basis_ = lfd::DmpParameters().num_basis;
  double smoothing_sigma_ = 0.0;
  std::optional<lfd::TimeAlignmentOptions> time_alignment_;
  lfd::FrameSelectionOptions frames_;
  double tf_timeout_ = 2.0;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "learner");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  const lfd_ros::MasterWatch master_watch;  // a restarted master: the node ends, to be respawned
  Learner learner(pnh);
  ros::ServiceServer srv = nh.advertiseService("learner/learn", &Learner::learn, &learner);
  ROS_INFO("learner: ready on /learner/learn");
  ros::spin();  // tf arrives on the listener's own thread while a request waits for it
  return master_watch.exitCode();
}
