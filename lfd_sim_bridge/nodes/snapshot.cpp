// snapshot: offscreen MuJoCo pictures of a recorded demonstration or reproduction, one PNG per
// requested time (by default the end of every ground-truth segment and the end of the bag).
//
//   snapshot --bag B [--times 8.3,12.9,end [--relative]] --out DIR [--model workcell.xml]
//            [--width 960] [--height 720] [--camera overview|free] [--lookat x,y,z]
//            [--distance d] [--azimuth deg] [--elevation deg]
//
// For each time the scene is rebuilt from the bag, not simulated: the joints by name from
// /joint_states and /objects/joint_states (the robot's joints, a drawer's slide), the free and the
// fixed objects from /objects/<body>/pose (the latest message at or before the time), then
// mj_forward and one offscreen render. Times are bag time (the recorded stamps, as the `segment`
// CLI reports changepoint_times), or seconds from the bag's start with --relative. Writes
// DIR/snapshot_<k>_<t>s.png and prints one "t file" line per picture.
//
// Rendering needs no display: an OSMesa context (libOSMesa, linked; MuJoCo's GL loader finds
// OSMesaGetProcAddress in the process). The pictures are encoded by libpng (png_file.hpp).
#include <GL/osmesa.h>
#include <mujoco/mujoco.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <geometry_msgs/PoseStamped.h>
#include <lfd_msgs/Phase.h>
#include <sensor_msgs/JointState.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <lfd_ros/ros_bag_message.hpp>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "lfd_sim_bridge/png_file.hpp"

namespace {

struct Options {
  std::string bag;
  std::string out;
  // The default robot's scene (LFD_SIM_MODEL_DIR, set by CMake); --model names another robot's.
  std::string model = (std::filesystem::path(LFD_SIM_MODEL_DIR) / "workcell.xml").string();
  std::string times;  // empty: segment ends
  bool relative = false;
  int width = 960;
  int height = 720;
  std::string camera = "free";
  std::array<double, 3> lookat{0.4, -0.15, 0.95};
  double distance = 2.4;
  double azimuth = 215.0;
  double elevation = -28.0;
};

[[noreturn]] void usage(const std::string& error) {
  std::cerr
      << "snapshot: " << error << "\n"
      << "usage: snapshot --bag B [--times t1,t2,...|end [--relative]] --out DIR\n"
         "                [--model MJCF]\n"
         "                [--width W] [--height H] [--camera overview|free|<MJCF camera>]\n"
         "                [--lookat x,y,z] [--distance d] [--azimuth deg] [--elevation deg]\n";
  std::exit(2);
}

double parseNumber(const std::string& text, const std::string& what) {
  try {
    std::size_t used = 0;
    double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument(text);
    return v;
  } catch (const std::exception&) {
    usage(what + ": '" + text + "' is not a number");
  }
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, sep))
    if (!part.empty()) parts.push_back(part);
  return parts;
}

Options parseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    std::string key = argv[i];
    if (key == "-h" || key == "--help") usage("help");
    if (key == "--relative") {
      o.relative = true;
      continue;
    }
    if (i + 1 >= argc) usage(key + " needs a value");
    std::string value = argv[++i];
    if (key == "--bag")
      o.bag = value;
    else if (key == "--out")
      o.out = value;
    else if (key == "--model")
      o.model = value;
    else if (key == "--times")
      o.times = value;
    else if (key == "--width")
      o.width = static_cast<int>(parseNumber(value, key));
    else if (key == "--height")
      o.height = static_cast<int>(parseNumber(value, key));
    else if (key == "--camera")
      o.camera = value;
    else if (key == "--distance")
      o.distance = parseNumber(value, key);
    else if (key == "--azimuth")
      o.azimuth = parseNumber(value, key);
    else if (key == "--elevation")
      o.elevation = parseNumber(value, key);
    else if (key == "--lookat") {
      auto parts = split(value, ',');
      if (parts.size() != 3) usage("--lookat needs x,y,z");
      for (int k = 0; k < 3; ++k) o.lookat[k] = parseNumber(parts[k], key);
    } else {
      usage("unknown option " + key);
    }
  }
  if (o.bag.empty()) usage("--bag is required");
  if (o.out.empty()) usage("--out is required");
  if (o.width < 16 || o.height < 16 || o.width > 4096 || o.height > 4096)
    usage("--width and --height must be within [16, 4096]");
  if (o.distance <= 0) usage("--distance must be positive");
  return o;
}

// ---- the bag's states -------------------------------------------------------------------------

template <typename Msg>
struct Stamped {
  double t;
  Msg msg;
};

struct Recording {
  double start = 0, end = 0;
  std::vector<Stamped<sensor_msgs::JointState>> joints;
  std::vector<Stamped<sensor_msgs::JointState>> object_joints;  // /objects/joint_states (a drawer)
  std::map<std::string, std::vector<Stamped<geometry_msgs::PoseStamped>>> objects;
  std::vector<double>
      segment_ends;  // last /lfd/phase message of each ground-truth phase but the last
};

Recording readRecording(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error("bag '" + path + "' does not exist");
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  if (view.size() == 0) throw std::runtime_error("bag '" + path + "' is empty");
  Recording r;
  r.start = view.getBeginTime().toSec();
  r.end = view.getEndTime().toSec();
  std::string phase;
  double phase_time = 0;
  std::map<std::string, std::size_t> seen;  // messages per topic, for errors
  for (const rosbag::MessageInstance& m : view) {
    const std::string& topic = m.getTopic();
    double t = m.getTime().toSec();
    const std::size_t k = seen[topic]++;
    // Bytes that do not fit the declared type are named (file, topic, type, index, time), not
    // roscpp's "Buffer Overrun".
    if (topic == "/joint_states") {
      if (auto js = lfd::instantiateChecked<sensor_msgs::JointState>(m, k, path))
        r.joints.push_back({t, *js});
    } else if (topic == "/objects/joint_states") {
      if (auto js = lfd::instantiateChecked<sensor_msgs::JointState>(m, k, path))
        r.object_joints.push_back({t, *js});
    } else if (topic.rfind("/objects/", 0) == 0 && topic.size() > 14 &&
               topic.compare(topic.size() - 5, 5, "/pose") == 0) {
      if (auto p = lfd::instantiateChecked<geometry_msgs::PoseStamped>(m, k, path))
        r.objects[topic.substr(9, topic.size() - 14)].push_back({t, *p});
    } else if (topic == "/lfd/phase") {
      if (auto p = lfd::instantiateChecked<lfd_msgs::Phase>(m, k, path)) {
        if (!phase.empty() && p->name != phase) r.segment_ends.push_back(phase_time);
        phase = p->name;
        phase_time = t;
      }
    }
  }
  if (r.joints.empty()) throw std::runtime_error("bag '" + path + "' has no /joint_states");
  return r;
}

// The latest sample at or before t (the first one if t precedes them all).
template <typename Msg>
const Msg& latest(const std::vector<Stamped<Msg>>& samples, double t) {
  auto it = std::upper_bound(samples.begin(), samples.end(), t,
                             [](double v, const Stamped<Msg>& s) { return v < s.t; });
  return it == samples.begin() ? it->msg : std::prev(it)->msg;
}

std::vector<double> requestedTimes(const Options& o, const Recording& r) {
  std::vector<double> times;
  if (o.times.empty()) {
    times = r.segment_ends;
    times.push_back(r.end);
    return times;
  }
  for (const std::string& part : split(o.times, ',')) {
    double t = part == "end" ? r.end : parseNumber(part, "--times");
    if (o.relative && part != "end") t += r.start;
    if (t < r.start - 1e-6 || t > r.end + 1e-6) {
      std::ostringstream msg;
      msg << "time " << part << " is outside the bag [" << r.start << ", " << r.end
          << "] s of bag time" << (o.relative ? "" : " (--relative: from the bag's start)");
      throw std::invalid_argument(msg.str());
    }
    times.push_back(t);
  }
  if (times.empty()) usage("--times lists no time");
  return times;
}

// ---- scene ------------------------------------------------------------------------------------

void setPose(const geometry_msgs::Pose& p, mjtNum* pos, mjtNum* quat) {
  pos[0] = p.position.x;
  pos[1] = p.position.y;
  pos[2] = p.position.z;
  quat[0] = p.orientation.w;
  quat[1] = p.orientation.x;
  quat[2] = p.orientation.y;
  quat[3] = p.orientation.z;
  mju_normalize4(quat);
}

void applyJoints(const mjModel* m, mjData* d, const sensor_msgs::JointState& js) {
  for (std::size_t k = 0; k < js.name.size() && k < js.position.size(); ++k) {
    int id = mj_name2id(m, mjOBJ_JOINT, js.name[k].c_str());
    if (id < 0) continue;  // a joint of the robot's description unknown to the scene
    if (m->jnt_type[id] != mjJNT_HINGE && m->jnt_type[id] != mjJNT_SLIDE) continue;
    d->qpos[m->jnt_qposadr[id]] = js.position[k];
  }
}

void applyState(const mjModel* m, mjData* d, const Recording& r, double t) {
  applyJoints(m, d, latest(r.joints, t));
  // Bags recorded before the split carry the drawer's slide on /joint_states (applied above).
  if (!r.object_joints.empty()) applyJoints(m, d, latest(r.object_joints, t));
  for (const auto& [name, samples] : r.objects) {
    const geometry_msgs::Pose& p = latest(samples, t).pose;
    const int body = mj_name2id(m, mjOBJ_BODY, name.c_str());
    if (body >= 0 && m->body_mocapid[body] >= 0) {  // a fixed object (the drawer's cabinet)
      const int k = m->body_mocapid[body];
      setPose(p, d->mocap_pos + 3 * k, d->mocap_quat + 4 * k);
      continue;
    }
    int id = mj_name2id(m, mjOBJ_JOINT, (name + "_free").c_str());
    if (id < 0 || m->jnt_type[id] != mjJNT_FREE) continue;  // a part moved by its joint (handle)
    setPose(p, d->qpos + m->jnt_qposadr[id], d->qpos + m->jnt_qposadr[id] + 3);
  }
  mj_forward(m, d);
}

// ---- offscreen GL -----------------------------------------------------------------------------

// An OSMesa context with its own pixel buffer.
class OffscreenGL {
 public:
  OffscreenGL(int width, int height) : buffer_(static_cast<std::size_t>(width) * height * 4) {
    context_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
    if (!context_) throw std::runtime_error("OSMesaCreateContextExt failed");
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height))
      throw std::runtime_error("OSMesaMakeCurrent failed");
  }
  ~OffscreenGL() {
    if (context_) OSMesaDestroyContext(context_);
  }
  OffscreenGL(const OffscreenGL&) = delete;
  OffscreenGL& operator=(const OffscreenGL&) = delete;

 private:
  OSMesaContext context_ = nullptr;
  std::vector<std::uint8_t> buffer_;
};

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

int run(const Options& o) {
  Recording rec = readRecording(o.bag);
  std::vector<double> times = requestedTimes(o, rec);

  char error[1000] = "";
  std::unique_ptr<mjModel, ModelDeleter> model(mj_loadXML(o.model.c_str(), nullptr, error, 1000));
  if (!model) throw std::runtime_error("cannot load '" + o.model + "': " + error);
  mjModel* m = model.get();
  std::unique_ptr<mjData, DataDeleter> data(mj_makeData(m));
  m->vis.global.offwidth = std::max(m->vis.global.offwidth, o.width);
  m->vis.global.offheight = std::max(m->vis.global.offheight, o.height);

  mjvCamera cam;
  mjv_defaultCamera(&cam);
  if (o.camera == "free") {
    cam.type = mjCAMERA_FREE;
    for (int k = 0; k < 3; ++k) cam.lookat[k] = o.lookat[k];
    cam.distance = o.distance;
    cam.azimuth = o.azimuth;
    cam.elevation = o.elevation;
  } else {
    cam.type = mjCAMERA_FIXED;
    cam.fixedcamid = mj_name2id(m, mjOBJ_CAMERA, o.camera.c_str());
    if (cam.fixedcamid < 0)
      throw std::invalid_argument("--camera: '" + o.camera +
                                  "' is neither 'free' nor a camera of " + o.model);
  }

  OffscreenGL gl(m->vis.global.offwidth, m->vis.global.offheight);
  mjvOption opt;
  mjv_defaultOption(&opt);
  mjvScene scene;
  mjv_defaultScene(&scene);
  mjv_makeScene(m, &scene, 2000);
  mjrContext con;
  mjr_defaultContext(&con);
  mjr_makeContext(m, &con, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &con);
  if (con.currentBuffer != mjFB_OFFSCREEN) throw std::runtime_error("no offscreen buffer");

  std::filesystem::create_directories(o.out);
  const mjrRect viewport{0, 0, o.width, o.height};
  std::vector<std::uint8_t> bottom_up(static_cast<std::size_t>(o.width) * o.height * 3);
  std::vector<std::uint8_t> rgb(bottom_up.size());
  for (std::size_t k = 0; k < times.size(); ++k) {
    applyState(m, data.get(), rec, times[k]);
    mjv_updateScene(m, data.get(), &opt, nullptr, &cam, mjCAT_ALL, &scene);
    mjr_render(viewport, &scene, &con);
    mjr_readPixels(bottom_up.data(), nullptr, viewport, &con);
    const std::size_t row = static_cast<std::size_t>(o.width) * 3;
    for (int y = 0; y < o.height; ++y)
      std::memcpy(rgb.data() + y * row, bottom_up.data() + (o.height - 1 - y) * row, row);
    char name[64];
    std::snprintf(name, sizeof(name), "snapshot_%02zu_%.2fs.png", k, times[k] - rec.start);
    std::string file = (std::filesystem::path(o.out) / name).string();
    lfd_sim_bridge::writePng(file, rgb, o.width, o.height);
    std::printf("%.3f %s\n", times[k] - rec.start, file.c_str());
  }
  mjr_freeContext(&con);
  mjv_freeScene(&scene);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parseOptions(argc, argv);
  try {
    return run(o);
  } catch (const std::exception& e) {
    std::cerr << "snapshot: " << e.what() << "\n";
    return 1;
  }
}
