// `sweetspot explore-merge [--progress=MODE] FILE...`: the shards of a sweep merged as
// streams (api/explore/merge_stream.hpp) onto stdout, in memory that does not grow with the
// sweep.
#pragma once

#include <string>
#include <vector>

#include "server/cli_progress.hpp"

namespace sweetspot::server {

/// Runs explore-merge on `files` (the arguments after `explore-merge`, `--progress=MODE`
/// already taken out): the merged sweep on stdout, exit 0; 2 when the shards do not make one
/// complete sweep (the reason on stderr, nothing on stdout); 1 when a file cannot be read or
/// stdout fails.
int ExploreMergeCommand(const std::vector<std::string>& files, const ProgressOptions& progress);

}  // namespace sweetspot::server
