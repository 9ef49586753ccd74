// Whether a recorder's subscriptions are really carrying data. roscpp counts a publisher as soon as
// it has asked it for the topic, before the publisher has taken the connection: whatever it
// publishes in between is lost. On a loaded CI machine that window lasted ~0.9 s of wall time, 7.5
// s of a sim running faster than real time, so a bag began 7.5 s late on four topics. A first
// message proves the link; so does the publisher's own list of its connections.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace lfd_sim_bridge {

using PublishersByTopic = std::map<std::string, std::vector<std::string>>;  // topic -> node names

// The topics of `expected` that some publisher the master lists has not delivered a message on yet
// (`heard_from`: topic -> publisher nodes a message came from). `exempt`, the node that asks for a
// recording, is not waited for: it publishes its own topics (e.g. /lfd/phase) only during one.
std::vector<std::string> topicsAwaitingData(
    const std::vector<std::string>& expected, const PublishersByTopic& publishers,
    const std::map<std::string, std::set<std::string>>& heard_from, const std::string& exempt);

// The topics on which `publisher_node` has taken a connection from `subscriber_node`: from the
// publisher's own bus info (the node API's getBusInfo, which `rosnode info` reads), so a link is
// known to be up even while nothing is published (a paused sim). Waits at most `timeout` s of wall
// time for the answer; false when the node cannot be asked.
bool topicsLinkedTo(const std::string& publisher_node, const std::string& subscriber_node,
                    double timeout, std::set<std::string>* topics);

// Every advertised topic and its publisher nodes, from the master (getSystemState). Returns false
// when the master does not answer.
bool publishersFromMaster(PublishersByTopic* publishers);

}  // namespace lfd_sim_bridge
