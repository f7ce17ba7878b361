// The stage registry (stages/stages.def): the coordinator's stage list, executables and in-process nodes
// come from it, every stage has its folder, and the channels it lists are those its node subscribes to.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "runtime/channels.hpp"
#include "runtime/pipeline/pipeline_config.hpp"
#include "runtime/pipeline/stage_nodes.hpp"
#include "runtime/pipeline/stage_registry.hpp"
#include "runtime/pipeline/stage_split.hpp"

namespace fusecal {
namespace {

// A bus that only records what is subscribed and published.
class RecordingBus : public Bus {
 public:
  std::string url() const override { return "recording://"; }
  void PublishRaw(const std::string& channel, const void*, size_t) override { published.insert(channel); }
  Subscription SubscribeRaw(const std::string& channel, RawHandler) override {
    subscribed.insert(channel);
    return Subscription();
  }
  int Handle(int) override { return 0; }
  std::set<std::string> subscribed, published;
};

std::set<std::string> AsSet(const std::vector<std::string>& names) { return {names.begin(), names.end()}; }

TEST(StageRegistry, IsTheCoordinatorsStageListInStartOrder) {
  std::vector<std::string> names;
  for (const StageInfo& stage : StageRegistry()) names.push_back(stage.name);
  EXPECT_EQ(names, KnownStageNames());
  ASSERT_FALSE(names.empty());
  EXPECT_EQ(names.front(), "ros2_input");  // the sensors come first, the ROS 2 output last
  EXPECT_EQ(names.back(), "ros2_tf");
  EXPECT_EQ(FindStage("fusion_odometry")->Executable(), "fusecal-fusion-odometry");
  EXPECT_EQ(FindStage("handeye")->Executable(), "fusecal-handeye");
  EXPECT_EQ(FindStage("no_such_stage"), nullptr);
}

TEST(StageRegistry, EveryStageHasItsFolderAndTestsAndListsPipelineChannels) {
  for (const StageInfo& stage : StageRegistry()) {
    EXPECT_TRUE(std::filesystem::is_directory(std::string(FUSECAL_SOURCE_DIR) + "/stages/" + stage.name)) << stage.name;
    EXPECT_TRUE(std::filesystem::is_directory(std::string(FUSECAL_SOURCE_DIR) + "/tests/stages/" + stage.name))
        << stage.name;
    for (const auto& channels : {stage.channels_in, stage.channels_out})
      for (const std::string& channel : channels)
        EXPECT_TRUE(IsPipelineChannel(channel)) << stage.name << ": " << channel;
    EXPECT_FALSE(stage.channels_in.empty() && stage.channels_out.empty()) << stage.name;
  }
}

TEST(StageRegistry, InProcessNodesSubscribeToTheChannelsTheRegistryLists) {
  const PipelineConfig config = LoadPipelineConfig(DefaultPipelineConfigPath());
  int in_process = 0;
  for (const StageInfo& stage : StageRegistry()) {
    auto node = MakeStageNode(stage.name, config);
    ASSERT_EQ(node != nullptr, stage.in_process) << stage.name;
    if (!node) continue;
    ++in_process;
    RecordingBus bus;
    node->Start(bus);
    EXPECT_EQ(bus.subscribed, AsSet(stage.channels_in)) << stage.name;
    for (const std::string& channel : bus.published)  // a node may publish at start (none need to)
      EXPECT_TRUE(AsSet(stage.channels_out).count(channel) || channel == channels::kStatus.name) << channel;
  }
  EXPECT_EQ(in_process, 5);  // stationarity, lidar_icp, camera_frontend, fusion_odometry, handeye
}

TEST(StageRegistry, CalibrateRunsTheInProcessStagesInStartOrder) {
  const PipelineConfig config = LoadPipelineConfig(DefaultPipelineConfigPath());
  std::vector<std::string> with, without;
  for (const auto& node : MakeStageNodes(config, true)) with.push_back(node.name);
  for (const auto& node : MakeStageNodes(config, false)) without.push_back(node.name);
  EXPECT_EQ(with,
            (std::vector<std::string>{"stationarity", "lidar_icp", "camera_frontend", "fusion_odometry", "handeye"}));
  EXPECT_EQ(without, (std::vector<std::string>{"lidar_icp", "camera_frontend", "fusion_odometry", "handeye"}));
}

}  // namespace
}  // namespace fusecal
