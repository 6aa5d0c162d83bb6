#include "server/static_files.hpp"

#include <limits.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <utility>

namespace sweetspot::server {
namespace {

// The build puts content-hashed bundle files (name-HASH.js) under this
// folder: their content never changes under one name.
constexpr std::string_view kHashedAssetsPrefix = "/assets/";

bool EndsWith(std::string_view text, std::string_view suffix) {
  return text.size() >= suffix.size() && text.substr(text.size() - suffix.size()) == suffix;
}

// The canonical absolute path of an existing file or folder ("" if none).
std::string RealPath(const std::string& path) {
  char resolved[PATH_MAX];
  if (realpath(path.c_str(), resolved) == nullptr) return {};
  return resolved;
}

// True when every '/'-separated segment of `relative` (no leading '/') is a
// plain file or folder name: not empty, not "." or "..", not hidden, no
// backslash or NUL.
bool SafeRelativePath(std::string_view relative) {
  if (relative.empty()) return false;
  std::size_t start = 0;
  while (start <= relative.size()) {
    const std::size_t end = std::min(relative.find('/', start), relative.size());
    const std::string_view segment = relative.substr(start, end - start);
    if (segment.empty() || segment.front() == '.') return false;  // "", ".", "..", hidden
    if (segment.find_first_of(std::string_view("\\\0", 2)) != std::string_view::npos) {
      return false;
    }
    start = end + 1;
  }
  return true;
}

}  // namespace

std::string DefaultWebRoot() {
  std::array<char, PATH_MAX> buffer{};
  const ssize_t n = readlink("/proc/self/exe", buffer.data(), buffer.size() - 1);
  if (n <= 0) return {};
  std::string exe(buffer.data(), static_cast<std::size_t>(n));
  const std::size_t slash = exe.rfind('/');
  if (slash == std::string::npos) return {};
  return exe.substr(0, slash) + "/web";
}

std::string ContentTypeFor(std::string_view file_name) {
  static constexpr std::pair<std::string_view, std::string_view> kTypes[] = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".ico", "image/x-icon"},
      {".txt", "text/plain; charset=utf-8"},
      {".woff2", "font/woff2"},
  };
  for (const auto& [extension, type] : kTypes) {
    if (EndsWith(file_name, extension)) return std::string(type);
  }
  return "application/octet-stream";
}

StaticFiles::StaticFiles(std::string root) : root_(std::move(root)) {}

bool StaticFiles::Installed() const { return Find("/").has_value(); }

std::optional<std::string> StaticFiles::Find(std::string_view path) const {
  if (root_.empty() || path.empty() || path.front() != '/') return std::nullopt;
  const std::string_view relative = path == "/" ? "index.html" : path.substr(1);
  if (!SafeRelativePath(relative)) return std::nullopt;
  const std::string real_root = RealPath(root_);
  if (real_root.empty()) return std::nullopt;
  const std::string real_file = RealPath(root_ + "/" + std::string(relative));
  // Symbolic links may not lead out of the root.
  if (real_file.size() <= real_root.size() + 1 ||
      real_file.compare(0, real_root.size(), real_root) != 0 ||
      real_file[real_root.size()] != '/') {
    return std::nullopt;
  }
  struct stat info {};
  if (stat(real_file.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) return std::nullopt;
  return real_file;
}

std::optional<StaticFile> StaticFiles::Read(const std::string& file) const {
  struct stat info {};
  if (stat(file.c_str(), &info) != 0 || !S_ISREG(info.st_mode) ||
      static_cast<unsigned long long>(info.st_size) > kMaxFileBytes) {
    return std::nullopt;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream bytes;
  bytes << in.rdbuf();
  if (!in && !in.eof()) return std::nullopt;
  StaticFile out;
  out.body = bytes.str();
  out.content_type = ContentTypeFor(file);
  const std::string real_root = RealPath(root_);
  const bool hashed =
      !real_root.empty() && file.size() > real_root.size() &&
      file.compare(0, real_root.size(), real_root) == 0 &&
      file.compare(real_root.size(), kHashedAssetsPrefix.size(), kHashedAssetsPrefix) == 0;
  out.cache_control = hashed ? "public, max-age=31536000, immutable" : "no-cache";
  char etag[64];
  std::snprintf(etag, sizeof etag, "\"%llx-%llx\"",
                static_cast<unsigned long long>(out.body.size()),
                static_cast<unsigned long long>(info.st_mtim.tv_sec) * 1000000000ULL +
                    static_cast<unsigned long long>(info.st_mtim.tv_nsec));
  out.etag = etag;
  return out;
}

}  // namespace sweetspot::server
