#include "server/cpu_quota.hpp"

#include <sched.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>

namespace sweetspot::server {
namespace {

// A positive decimal integer below 2^62, all of `text`.
std::optional<long long> Positive(std::string_view text) {
  if (text.empty() || text.size() > 18) return std::nullopt;
  long long value = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + (c - '0');
  }
  if (value <= 0) return std::nullopt;
  return value;
}

std::optional<std::string> ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

std::optional<int> CpusFromCpuMax(std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
  const std::size_t space = text.find(' ');
  if (space == std::string_view::npos) return std::nullopt;
  const std::string_view quota = text.substr(0, space);
  const std::optional<long long> period = Positive(text.substr(space + 1));
  if (!period) return std::nullopt;
  if (quota == "max") return std::nullopt;
  const std::optional<long long> q = Positive(quota);
  if (!q) return std::nullopt;
  const long long cpus = (*q + *period - 1) / *period;
  return static_cast<int>(std::clamp<long long>(cpus, 1, 1 << 20));
}

std::optional<std::string> OwnCgroupFolder(const std::string& proc_self_cgroup_text,
                                           const std::string& mount) {
  std::istringstream lines(proc_self_cgroup_text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("0::", 0) != 0) continue;  // cgroup v2's one hierarchy
    std::string path = line.substr(3);
    if (path.empty() || path.front() != '/') return std::nullopt;
    while (path.size() > 1 && path.back() == '/') path.pop_back();
    return path == "/" ? mount : mount + path;
  }
  return std::nullopt;
}

std::optional<int> CpusFromCfs(std::string_view quota_us, std::string_view period_us) {
  const auto trim = [](std::string_view t) {
    while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.remove_suffix(1);
    return t;
  };
  quota_us = trim(quota_us);
  if (quota_us == "-1") return std::nullopt;
  return CpusFromCpuMax(std::string(quota_us) + " " + std::string(trim(period_us)));
}

std::optional<std::string> OwnCgroupV1CpuFolder(const std::string& proc_self_cgroup_text,
                                                const std::string& mount) {
  std::istringstream lines(proc_self_cgroup_text);
  std::string line;
  while (std::getline(lines, line)) {
    const std::size_t first = line.find(':');
    const std::size_t second = first == std::string::npos ? first : line.find(':', first + 1);
    if (second == std::string::npos) continue;
    std::istringstream controllers(line.substr(first + 1, second - first - 1));
    std::string controller;
    bool cpu = false;
    while (std::getline(controllers, controller, ',')) cpu = cpu || controller == "cpu";
    if (!cpu) continue;
    std::string path = line.substr(second + 1);
    if (path.empty() || path.front() != '/') return std::nullopt;
    while (path.size() > 1 && path.back() == '/') path.pop_back();
    return path == "/" ? mount + "/cpu" : mount + "/cpu" + path;
  }
  return std::nullopt;
}

std::optional<int> CgroupCpuQuota() {
  const std::optional<std::string> self = ReadText("/proc/self/cgroup");
  if (!self) return std::nullopt;
  std::string mount = "/sys/fs/cgroup";
  std::optional<std::string> folder = OwnCgroupFolder(*self, mount);
  const bool v1 = !folder || !ReadText(mount + "/cgroup.controllers");
  if (v1) {
    folder = OwnCgroupV1CpuFolder(*self, mount);
    mount += "/cpu";
  }
  std::optional<int> quota;
  // A quota on a parent limits its children too (a pod's on its containers): the smallest.
  // In a container the path may be the host's, absent here: the walk reaches the mount.
  while (folder) {
    std::optional<int> cpus;
    if (!v1) {
      if (const std::optional<std::string> text = ReadText(*folder + "/cpu.max")) {
        cpus = CpusFromCpuMax(*text);
      }
    } else {
      const std::optional<std::string> q = ReadText(*folder + "/cpu.cfs_quota_us");
      const std::optional<std::string> p = ReadText(*folder + "/cpu.cfs_period_us");
      if (q && p) cpus = CpusFromCfs(*q, *p);
    }
    if (cpus) quota = quota ? std::min(*quota, *cpus) : *cpus;
    if (*folder == mount) break;
    const std::size_t slash = folder->rfind('/');
    if (slash == std::string::npos || slash < mount.size()) break;
    folder = slash == mount.size() ? mount : folder->substr(0, slash);
  }
  return quota;
}

std::optional<int> AffinityCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) != 0) return std::nullopt;
  const int count = CPU_COUNT(&set);
  if (count <= 0) return std::nullopt;
  return count;
}

int DefaultThreadCount() {
  const unsigned cores = std::thread::hardware_concurrency();
  int threads = cores == 0 ? 1 : static_cast<int>(cores);
  if (const std::optional<int> affinity = AffinityCpus()) threads = *affinity;
  if (const std::optional<int> quota = CgroupCpuQuota()) threads = std::min(threads, *quota);
  return std::max(1, threads);
}

}  // namespace sweetspot::server
