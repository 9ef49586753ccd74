// Master-free unit tests of the recorder's "is data flowing" rule: a topic waits until each of
// its publishers (but the node asking for the recording) has delivered a message.
#include <gtest/gtest.h>

#include "lfd_sim_bridge/topic_connections.hpp"

using lfd_sim_bridge::topicsAwaitingData;

TEST(TopicConnections, ATopicWaitsUntilEachPublisherHasSent) {
  const std::vector<std::string> expected = {"/joint_states", "/wrist_ft", "/imu"};
  const lfd_sim_bridge::PublishersByTopic publishers = {{"/joint_states", {"/bridge"}},
                                                        {"/wrist_ft", {"/bridge", "/ft_driver"}},
                                                        {"/imu", {"/bridge"}}};
  std::map<std::string, std::set<std::string>> heard = {{"/joint_states", {"/bridge"}},
                                                        {"/wrist_ft", {"/bridge"}}};
  EXPECT_EQ(topicsAwaitingData(expected, publishers, heard, "/demonstrator"),
            (std::vector<std::string>{"/wrist_ft", "/imu"}));
  heard["/wrist_ft"].insert("/ft_driver");
  heard["/imu"].insert("/bridge");
  EXPECT_TRUE(topicsAwaitingData(expected, publishers, heard, "/demonstrator").empty());
}

TEST(TopicConnections, UnpublishedTopicsAndTheCallersOwnAreNotWaitedFor) {
  // /lfd/phase is published by the demonstrator only while it records; /touch has no publisher.
  const std::vector<std::string> expected = {"/lfd/phase", "/touch", "/joint_states"};
  const lfd_sim_bridge::PublishersByTopic publishers = {{"/lfd/phase", {"/demonstrator"}},
                                                        {"/joint_states", {"/bridge"}}};
  EXPECT_TRUE(
      topicsAwaitingData(expected, publishers, {{"/joint_states", {"/bridge"}}}, "/demonstrator")
          .empty());
  // Another node asking for the recording does wait for the demonstrator's topic.
  EXPECT_EQ(topicsAwaitingData(expected, publishers, {{"/joint_states", {"/bridge"}}}, "/test"),
            (std::vector<std::string>{"/lfd/phase"}));
}
