// The design explorer's static files (web/, bundled by the build): GET / and
// the bundle's files from one folder, with a Content-Type per extension,
// cache headers, and no way out of the folder.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace sweetspot::server {

/// The default web root: the folder "web" next to the running executable
/// (read from /proc/self/exe); "" when the executable's path is unknown.
std::string DefaultWebRoot();

/// The Content-Type for a file name by its extension (text types with
/// charset=utf-8); "application/octet-stream" for an unknown extension.
std::string ContentTypeFor(std::string_view file_name);

/// One file ready to send.
struct StaticFile {
  std::string body;           ///< The file's bytes.
  std::string content_type;   ///< From the extension (ContentTypeFor).
  std::string cache_control;  ///< "no-cache" for HTML, a year + immutable for hashed assets.
  std::string etag;           ///< A strong validator from size and modification time.
};

/// Files under one folder, looked up per request (a rebuilt bundle is served
/// without a restart). Thread-safe: it holds no mutable state.
class StaticFiles {
 public:
  /// Largest file served, bytes (the bundle is far smaller).
  static constexpr std::size_t kMaxFileBytes = 16u << 20;

  /// Serves files under `root`; the folder need not exist (then nothing is
  /// Installed() and Find() finds nothing).
  explicit StaticFiles(std::string root);

  /// The folder as configured.
  const std::string& root() const { return root_; }
  /// True when the root is a folder with an index.html (the explorer is installed).
  bool Installed() const;
  /// The real path of the file that URL path `path` names ("/" =
  /// index.html), if it is a regular file inside the root. Refuses (nullopt) any path with an
  /// empty,
  /// "." or ".." segment, a segment starting with '.', a backslash or NUL,
  /// and any file whose real path (symbolic links resolved) leaves the root.
  std::optional<std::string> Find(std::string_view path) const;
  /// Reads the file Find() returned; nullopt when it cannot be read or is
  /// over kMaxFileBytes. Files under the root's "assets/" folder (named by
  /// their content hash) may be cached for a year; others are revalidated.
  std::optional<StaticFile> Read(const std::string& file) const;

 private:
  std::string root_;
};

}  // namespace sweetspot::server
