#include "lfd_sim_bridge/topic_connections.hpp"

#include <ros/master.h>
#include <ros/network.h>
#include <ros/this_node.h>
#include <xmlrpcpp/XmlRpcClient.h>
#include <xmlrpcpp/XmlRpcException.h>

namespace lfd_sim_bridge {
namespace {

// XmlRpcClient::execute waits for its answer forever: a node that hangs must not hang its caller.
class BoundedXmlRpcClient : public XmlRpc::XmlRpcClient {
 public:
  using XmlRpc::XmlRpcClient::XmlRpcClient;

  bool call(const char* method, const XmlRpc::XmlRpcValue& params, XmlRpc::XmlRpcValue* result,
            double timeout) {
    _isFault = false;
    if (!setupConnection() || !generateRequest(method, params)) return false;
    _disp.work(timeout);  // returns once the answer is read (the client leaves the dispatcher)
    return _connectionState == IDLE && parseResponse(*result) && !_isFault;
  }
};

bool nodeUri(const std::string& node, std::string* uri) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = node;
  if (!ros::master::execute("lookupNode", request, response, payload, false) ||
      payload.getType() != XmlRpc::XmlRpcValue::TypeString)
    return false;
  *uri = static_cast<std::string>(payload);
  return true;
}

}  // namespace

std::vector<std::string> topicsAwaitingData(
    const std::vector<std::string>& expected, const PublishersByTopic& publishers,
    const std::map<std::string, std::set<std::string>>& heard_from, const std::string& exempt) {
  static const std::set<std::string> kNone;
  std::vector<std::string> awaiting;
  for (const std::string& topic : expected) {
    const auto listed = publishers.find(topic);
    if (listed == publishers.end()) continue;
    const auto heard = heard_from.find(topic);
    const std::set<std::string>& senders = heard == heard_from.end() ? kNone : heard->second;
    for (const std::string& node : listed->second)
      if (node != exempt && !senders.count(node)) {
        awaiting.push_back(topic);
        break;
      }
  }
  return awaiting;
}

bool topicsLinkedTo(const std::string& publisher_node, const std::string& subscriber_node,
                    double timeout, std::set<std::string>* topics) {
  std::string uri, host;
  uint32_t port = 0;
  if (!nodeUri(publisher_node, &uri) || !ros::network::splitURI(uri, host, port)) return false;
  BoundedXmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue request, response;
  request[0] = ros::this_node::getName();
  if (!client.call("getBusInfo", request, &response, timeout)) return false;
  // [code, status, [[id, destination, direction, transport, topic, ...], ...]]
  try {
    if (response.getType() != XmlRpc::XmlRpcValue::TypeArray || response.size() < 3 ||
        static_cast<int>(response[0]) != 1)
      return false;
    XmlRpc::XmlRpcValue& links = response[2];
    for (int i = 0; i < links.size(); ++i) {
      XmlRpc::XmlRpcValue& link = links[i];
      if (link.getType() != XmlRpc::XmlRpcValue::TypeArray || link.size() < 5) continue;
      if (static_cast<std::string>(link[1]) == subscriber_node &&
          static_cast<std::string>(link[2]) == "o")
        topics->insert(static_cast<std::string>(link[4]));
    }
  } catch (const XmlRpc::XmlRpcException&) {
    return false;  // not the node API's answer
  }
  return true;
}

bool publishersFromMaster(PublishersByTopic* publishers) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, false)) return false;
  // payload: [publishers, subscribers, services], each a list of [name, [node, ...]].
  if (payload.getType() != XmlRpc::XmlRpcValue::TypeArray || payload.size() < 1) return false;
  publishers->clear();
  try {
    XmlRpc::XmlRpcValue& published = payload[0];
    for (int i = 0; i < published.size(); ++i) {
      XmlRpc::XmlRpcValue& entry = published[i];
      if (entry.getType() != XmlRpc::XmlRpcValue::TypeArray || entry.size() < 2) continue;
      std::vector<std::string>& nodes = (*publishers)[static_cast<std::string>(entry[0])];
      for (int j = 0; j < entry[1].size(); ++j)
        nodes.push_back(static_cast<std::string>(entry[1][j]));
    }
  } catch (const XmlRpc::XmlRpcException&) {
    return false;
  }
  return true;
}

}  // namespace lfd_sim_bridge
