// iceoryx shared memory: RouDi's pools planned from the largest message, the /dev/shm check that comes
// before them, and a RouDi started, killed and started again. Needs iox-roudi (tools/setup installs it)
// and no other RouDi on the machine (ctest keeps the RouDi tests apart with RESOURCE_LOCK roudi).
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "runtime/shared_memory.hpp"

namespace fusecal::shm {
namespace {

std::string TempDir(const std::string& name) {
  return ::testing::TempDir() + "fusecal_shm_" + std::to_string(getpid()) + "_" + name;
}

TEST(SharedMemoryPools, LargestChunkHoldsTheLargestMessage) {
  for (size_t max_message : {size_t{100000}, size_t{6000000}, size_t{12600000}, size_t{40} << 20}) {
    const PoolPlan plan = PlanPools(max_message, 32);
    EXPECT_GE(plan.largest_chunk(), max_message + kChunkOverheadBytes) << max_message;
    EXPECT_GE(LargestShmMessage(plan), max_message) << max_message;
    EXPECT_EQ(plan.pools.back().count, 32);
    for (const auto& pool : plan.pools) EXPECT_EQ(pool.chunk_bytes % 32, 0u) << "iceoryx wants 32-byte multiples";
    for (size_t i = 1; i < plan.pools.size(); ++i) EXPECT_LT(plan.pools[i - 1].chunk_bytes, plan.pools[i].chunk_bytes);
  }
}

TEST(SharedMemoryPools, TomlListsEveryPool) {
  const PoolPlan plan = PlanPools(6000000, 8);
  const std::string toml = RoudiConfigToml(plan);
  EXPECT_NE(toml.find("[general]\nversion = 1"), std::string::npos) << toml;
  for (const auto& pool : plan.pools) {
    std::ostringstream entry;
    entry << "size = " << pool.chunk_bytes << "\ncount = " << pool.count;
    EXPECT_NE(toml.find(entry.str()), std::string::npos) << entry.str() << "\n" << toml;
  }
}

TEST(SharedMemoryPools, SmallDevShmIsRefusedWithTheFix) {
  const PoolPlan plan = PlanPools(kDefaultMaxMessageBytes, kDefaultBulkChunks);
  ShmSpace container_default{true, 64u << 20, 64u << 20};  // docker's default /dev/shm
  const std::string problem = CheckPlanFits(plan, container_default);
  EXPECT_NE(problem.find("SIGBUS"), std::string::npos) << problem;
  EXPECT_NE(problem.find("mount -o remount,size="), std::string::npos) << problem;
  EXPECT_NE(problem.find("--shm-size="), std::string::npos) << problem;
  EXPECT_NE(CheckPlanFits(plan, ShmSpace{}).find("does not exist"), std::string::npos);
  ShmSpace roomy{true, 8ull << 30, 8ull << 30};
  EXPECT_EQ(CheckPlanFits(plan, roomy), "");
}

TEST(SharedMemoryPools, QueriesARealFilesystem) {
  const ShmSpace tmp = QueryShmSpace("/tmp");
  EXPECT_TRUE(tmp.exists);
  EXPECT_GT(tmp.total_bytes, 0u);
  EXPECT_FALSE(QueryShmSpace("/no/such/dir").exists);
}

TEST(Roudi, PlanLargerThanDevShmFailsBeforeStarting) {
  // A RouDi left to end by the previous test binary may still be going (it takes a moment).
  ASSERT_TRUE(WaitUntilRoudiGone()) << "another RouDi is running on this machine; stop it to run this test";
  RoudiProcess roudi(TempDir("huge"), PlanPools(size_t{1} << 30, 1024));  // 1 TiB of chunks
  try {
    roudi.Start();
    FAIL() << "a 1 TiB plan was started";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/shm"), std::string::npos) << e.what();
  }
  EXPECT_EQ(roudi.pid(), -1);
  EXPECT_FALSE(RoudiRunning());
}

TEST(Roudi, StartsAnswersDiesAndStartsAgain) {
  ASSERT_FALSE(RoudiExecutable().empty()) << "iox-roudi missing: tools/setup installs package iceoryx";
  ASSERT_TRUE(WaitUntilRoudiGone()) << "another RouDi is running on this machine; stop it to run this test";
  RoudiProcess roudi(TempDir("cycle"), PlanPools(1 << 20, 4));
  roudi.Start();
  EXPECT_TRUE(roudi.Alive());
  EXPECT_TRUE(RoudiRunning());
  std::ifstream config(roudi.config_path());
  EXPECT_TRUE(config.good()) << roudi.config_path();
  // A second RouDi is refused with a message, not started beside the first.
  RoudiProcess second(TempDir("second"), PlanPools(1 << 20, 4));
  EXPECT_THROW(second.Start(), std::runtime_error);
  // Killed without a chance to clean up: the socket goes stale, and a new start must still work.
  kill(roudi.pid(), SIGKILL);
  for (int i = 0; i < 100 && roudi.Alive(); ++i) usleep(20000);
  EXPECT_FALSE(roudi.Alive());
  EXPECT_FALSE(RoudiRunning());
  roudi.Start();
  EXPECT_TRUE(RoudiRunning());
  EXPECT_EQ(roudi.starts(), 2);
  roudi.Stop();
  EXPECT_FALSE(roudi.Alive());
  EXPECT_FALSE(RoudiRunning());
}

}  // namespace
}  // namespace fusecal::shm
