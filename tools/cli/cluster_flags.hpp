#pragma once
// The cluster flags of run and play (--node, --join-timeout, --rate): built with the driver only.
#include <CLI/CLI.hpp>
#include <string>

#include "facet/driver/cluster.hpp"

namespace facet::cli {

// --node's check (run, play): a name, not empty (an empty one would run every projector alone).
CLI::Validator cluster_node_name();

// --node NAME, --join-timeout S and --rate HZ of run and play into `request` (frames_given is the
// command's to set); `verb` begins --node's help ("Run", "Play").
void add_cluster_flags(CLI::App& command, driver::ClusterRequest& request, const std::string& verb);

}  // namespace facet::cli
