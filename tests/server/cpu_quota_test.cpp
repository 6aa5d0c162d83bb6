// The default thread count's sources (server/cpu_quota.hpp): cgroup v2 cpu.max (v1: cpu.cfs_*)
// and the cgroup folder of /proc/self/cgroup. The affinity path is tested with `taskset` in cli_merge_test.cpp.
#include "server/cpu_quota.hpp"

#include <gtest/gtest.h>

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace cpu_quota_test {
namespace {

TEST(CpuQuotaTest, CpuMaxGivesTheQuotaOverThePeriodRoundedUp) {
  EXPECT_EQ(CpusFromCpuMax("max 100000"), std::nullopt);  // no quota
  EXPECT_EQ(CpusFromCpuMax("max 100000\n"), std::nullopt);
  EXPECT_EQ(CpusFromCpuMax("150000 100000"), 2);  // 1.5 CPUs: 2 threads, each throttled less
  EXPECT_EQ(CpusFromCpuMax("150000 100000\n"), 2);
  EXPECT_EQ(CpusFromCpuMax("50000 100000"), 1);  // half a CPU: still one thread
  EXPECT_EQ(CpusFromCpuMax("200000 100000"), 2);
  EXPECT_EQ(CpusFromCpuMax("400000 50000"), 8);
  EXPECT_EQ(CpusFromCpuMax("1 100000"), 1);
  for (const char* bad : {"", "max", "100000", "-5 100000", "100000 0", "abc 100000",
                          "100000 100000 7", "1e5 100000"}) {
    EXPECT_EQ(CpusFromCpuMax(bad), std::nullopt) << bad;
  }
}

TEST(CpuQuotaTest, TheCgroupFolderIsTheV2LineUnderTheMount) {
  EXPECT_EQ(OwnCgroupFolder("0::/kubepods/pod1/ctr\n"), "/sys/fs/cgroup/kubepods/pod1/ctr");
  EXPECT_EQ(OwnCgroupFolder("0::/\n"), "/sys/fs/cgroup");
  EXPECT_EQ(OwnCgroupFolder("12:cpu,cpuacct:/x\n0::/user.slice/\n", "/cg"), "/cg/user.slice");
  EXPECT_EQ(OwnCgroupFolder("4:memory:/a\n1:cpu:/\n"), std::nullopt);  // cgroup v1 only
  EXPECT_EQ(OwnCgroupFolder(""), std::nullopt);
}

TEST(CpuQuotaTest, CgroupV1GivesTheCfsQuotaOverItsPeriod) {
  EXPECT_EQ(CpusFromCfs("-1\n", "100000\n"), std::nullopt);  // no quota
  EXPECT_EQ(CpusFromCfs("150000\n", "100000\n"), 2);
  EXPECT_EQ(CpusFromCfs("50000", "100000"), 1);
  EXPECT_EQ(CpusFromCfs("50000", "0"), std::nullopt);
  EXPECT_EQ(OwnCgroupV1CpuFolder("4:memory:/a\n2:cpu,cpuacct:/docker/abc\n"),
            "/sys/fs/cgroup/cpu/docker/abc");
  EXPECT_EQ(OwnCgroupV1CpuFolder("2:cpuacct:/x\n1:cpu:/\n0::/\n"), "/sys/fs/cgroup/cpu");
  EXPECT_EQ(OwnCgroupV1CpuFolder("2:cpuacct,cpuset:/x\n0::/\n"), std::nullopt);
}

TEST(CpuQuotaTest, TheDefaultIsAtLeastOneAndAtMostTheAffinity) {
  const int threads = DefaultThreadCount();
  EXPECT_GE(threads, 1);
  if (const auto affinity = AffinityCpus()) {
    EXPECT_LE(threads, *affinity);
  }
}

}  // namespace
}  // namespace cpu_quota_test
}  // namespace sweetspot::server
