#include "cluster_flags.hpp"

namespace facet::cli {

void add_cluster_flags(CLI::App& command, driver::ClusterRequest& request,
                       const std::string& verb) {
  command
      .add_option("--node", request.node,
                  verb +
                      " as this node of the display.json's cluster: its projectors only, "
                      "frame-locked with the others (see README: Clusters)")
      ->check(cluster_node_name());
  command
      .add_option("--join-timeout", request.join_timeout_s,
                  "Cluster: seconds the master waits for the nodes to join, and a node for the "
                  "master's first word")
      ->capture_default_str();
  command.add_option("--rate", request.rate_hz,
                     "Cluster master: at most this many frames per second (default: as fast as "
                     "the slowest node)");
}

CLI::Validator cluster_node_name() {
  return CLI::Validator(
      [](const std::string& name) {
        return name.empty()
                   ? std::string("expected the name of a node of the display.json's cluster")
                   : std::string();
      },
      "NAME");
}

}  // namespace facet::cli
