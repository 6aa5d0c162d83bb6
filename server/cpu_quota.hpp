// How many threads this process should run its models on by default: the CPUs it may use,
// not the node's cores. A container or a Slurm/Kubernetes job limited to 1 CPU on a 64-core
// node gets 1, not 64 (a thread per core there is throttled by the quota).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace sweetspot::server {

/// The CPUs a cgroup v2 `cpu.max` text allows: quota / period rounded up, at least 1
/// ("150000 100000" -> 2, "50000 100000" -> 1); nullopt for "max ..." (no quota) and for
/// text that is not "<quota|max> <period>" with positive integers.
std::optional<int> CpusFromCpuMax(std::string_view text);

/// The cgroup v2 folder of this process from /proc/self/cgroup's "0::<path>" line, under
/// `mount` (default /sys/fs/cgroup); nullopt when there is none (cgroup v1, no /proc).
std::optional<std::string> OwnCgroupFolder(const std::string& proc_self_cgroup_text,
                                           const std::string& mount = "/sys/fs/cgroup");

/// cgroup v1's form of the same: `cpu.cfs_quota_us` ("-1": no quota) over
/// `cpu.cfs_period_us`, rounded up, at least 1.
std::optional<int> CpusFromCfs(std::string_view quota_us, std::string_view period_us);

/// The cgroup v1 cpu controller's folder from /proc/self/cgroup's "N:...cpu...:<path>" line
/// (the controller list holding "cpu"), under `mount`/cpu; nullopt when there is none.
std::optional<std::string> OwnCgroupV1CpuFolder(const std::string& proc_self_cgroup_text,
                                                const std::string& mount = "/sys/fs/cgroup");

/// The smallest quota of this process's cgroup and its parents' (each folder's cpu.max,
/// walking up to the mount; on cgroup v1 its cpu controller's cpu.cfs_quota_us and
/// cpu.cfs_period_us), or nullopt when none sets one.
std::optional<int> CgroupCpuQuota();

/// CPUs in this process's affinity mask (sched_getaffinity; `taskset -c 0` gives 1), or
/// nullopt when it cannot be read.
std::optional<int> AffinityCpus();

/// The default thread count: min(affinity CPUs, cgroup quota), each when known, else
/// std::thread::hardware_concurrency(), at least 1.
int DefaultThreadCount();

}  // namespace sweetspot::server
