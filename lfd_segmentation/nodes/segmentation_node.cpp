// Segmentation service node: advertises ~segment (/segmentation/segment when the node is named
// "segmentation", as in lfd_launch/segment.launch) of type lfd_msgs/Segment. Parameters are the
// node's private namespace, loaded from config/segmentation.yaml. A failing request returns
// success=false with an error; the node stays up.
#include <ros/ros.h>
#include <yaml-cpp/yaml.h>

#include "lfd_core/util/heap_trim.hpp"
#include "lfd_ros/master_watch.hpp"
#include "lfd_segmentation/segment_service.hpp"

namespace {

// The private parameter tree (XmlRpc) as YAML, so the node and the CLI share one parser.
YAML::Node toYaml(const XmlRpc::XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(const_cast<XmlRpc::XmlRpcValue&>(v)));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(const_cast<XmlRpc::XmlRpcValue&>(v)));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return YAML::Node(static_cast<double>(const_cast<XmlRpc::XmlRpcValue&>(v)));
    case XmlRpc::XmlRpcValue::TypeString:
      return YAML::Node(static_cast<std::string>(const_cast<XmlRpc::XmlRpcValue&>(v)));
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node out(YAML::NodeType::Sequence);
      for (int k = 0; k < v.size(); ++k)
        out.push_back(toYaml(const_cast<XmlRpc::XmlRpcValue&>(v)[k]));
      return out;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      YAML::Node out(YAML::NodeType::Map);
      for (const auto& [key, value] : const_cast<XmlRpc::XmlRpcValue&>(v)) out[key] = toYaml(value);
      return out;
    }
    default:
      return YAML::Node();
  }
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "segmentation");
  ros::NodeHandle pnh("~");
  const lfd_ros::MasterWatch master_watch;  // a restarted master: the node ends, to be respawned
  XmlRpc::XmlRpcValue tree;
  YAML::Node root(YAML::NodeType::Map);
  if (ros::param::get(ros::this_node::getName(), tree)) root = toYaml(tree);
  lfd_segmentation::SegmentationParams params;
  try {
    params = lfd_segmentation::paramsFromYaml(root);
  } catch (const std::exception& e) {
    ROS_FATAL("segmentation: bad parameters: %s", e.what());
    return 1;
  }
  if (params.topics.empty()) {
    ROS_WARN(
        "segmentation: no ~topics configured; every request will fail (load "
        "config/segmentation.yaml)");
  }
  lfd_segmentation::PreparedCache cache;  // requests are served one at a time
  auto callback = [&params, &cache](lfd_msgs::Segment::Request& req,
                                    lfd_msgs::Segment::Response& res) {
    const lfd::TrimHeapOnExit trim;  // what the request freed goes back to the system
    ROS_INFO("segmentation: request with %zu bag(s)", req.bag_paths.size());
    lfd_segmentation::handleSegmentRequest(params, req, res, &cache);
    for (const std::string& w : res.warnings) ROS_WARN("segmentation: %s", w.c_str());
    if (res.success) {
      std::string summary;
      for (const auto& d : res.demos) summary += " " + std::to_string(d.changepoints.size());
      ROS_INFO("segmentation: done in %.2f s; validated changepoints per demo:%s", res.elapsed,
               summary.c_str());
    } else {
      ROS_ERROR("segmentation: request failed: %s", res.error.c_str());
    }
    return true;  // the error travels in the response, the call itself succeeds
  };
  ros::ServiceServer server =
      pnh.advertiseService<lfd_msgs::Segment::Request, lfd_msgs::Segment::Response>("segment",
                                                                                    callback);
  ROS_INFO("segmentation: serving %s (%zu topics, %.0f Hz)", server.getService().c_str(),
           params.topics.size(), params.rate);
  ros::spin();
  return master_watch.exitCode();
}
