// facet bench --scenario cluster: the cluster protocol's cost per frame and its loss detection,
// with nodes on threads that render nothing.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "facet/driver/cluster.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

// A loopback TCP port nobody listens on now (the kernel's choice for port 0).
int free_loopback_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), size) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size) == 0)
    port = ntohs(address.sin_port);
  ::close(fd);
  return port;
}

projection_io::DisplayCluster bench_cluster_config(int nodes, const std::string& transport,
                                                   const std::filesystem::path& folder,
                                                   double deadline_ms) {
  projection_io::DisplayCluster cluster;
  for (int k = 0; k < nodes; ++k) {
    const std::string name = "n" + std::to_string(k);
    std::string address;
    if (transport == "tcp") {
      // Two ports each: the barrier listens on the next one.
      int port = 0;
      do port = free_loopback_port();
      while (port == 0 || port >= 65534);
      address = "tcp://127.0.0.1:" + std::to_string(port);
    } else {
      address = "ipc://" + (folder / name).string();
    }
    cluster.nodes.push_back({name, address, {"p" + std::to_string(k)}, false});
  }
  cluster.master = "n0";
  cluster.deadline_ms = deadline_ms;
  return cluster;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const auto index = std::min(values.size() - 1, std::size_t(p * double(values.size() - 1) + 0.5));
  return values[index];
}

}  // namespace

std::vector<ClusterBenchRow> bench_cluster(
    const ClusterBenchOptions& options, const std::function<void(const std::string&)>& progress) {
  if (options.frames < 10) throw InputError("command line", "--frames", "at least 10 frames");
  std::vector<ClusterBenchRow> rows;
  for (const std::string& transport : options.transports) {
    for (const int nodes : options.node_counts) {
      const projection_io::DisplayCluster cluster =
          bench_cluster_config(nodes, transport, options.folder, options.deadline_ms);
      auto node_options = [&](int k) {
        ClusterNodeOptions o;
        o.cluster = cluster;
        o.source = "bench";
        o.node = cluster.nodes[std::size_t(k)].name;
        o.content_digest = 1;
        o.join_timeout = std::chrono::milliseconds(30'000);
        o.report = [](const std::string&) {};
        return o;
      };
      // With 3 nodes or more, the last secondary falls silent after `frames` frames, as a killed
      // node would; the others run until the master falls silent, and note when they give up.
      const std::uint64_t frames = std::uint64_t(options.frames);
      const int silent_node = nodes >= 3 ? nodes - 1 : -1;
      std::vector<Clock::time_point> gave_up(static_cast<std::size_t>(nodes));
      std::vector<std::thread> secondaries;
      for (int k = 1; k < nodes; ++k) {
        secondaries.emplace_back([&, k] {
          std::unique_ptr<FrameSync> sync;  // torn down after the time is taken
          try {
            sync = make_cluster_secondary(node_options(k));
            while (const std::optional<FrameState> state = sync->next_frame(FrameState{})) {
              if (k == silent_node && state->frame >= frames) break;  // silent from here on
              nlohmann::json stats;
              sync->ready_to_swap(*state, stats);
            }
          } catch (const PeerLost&) {
          }
          gave_up[std::size_t(k)] = Clock::now();
        });
      }
      ClusterBenchRow row;
      row.nodes = nodes;
      row.transport = transport;
      std::vector<double> frame_ms;
      {
        const std::unique_ptr<FrameSync> master = make_cluster_master(node_options(0));
        // Frames 0..frames-1 timed; frame `frames` finds the silent node silent.
        const std::uint64_t last = silent_node > 0 ? frames + 1 : frames;
        for (std::uint64_t frame = 0; frame < last; ++frame) {
          FrameState own;
          own.frame = frame;
          own.time_s = double(frame) / 60;
          const Clock::time_point start = Clock::now();
          const std::optional<FrameState> state = master->next_frame(own);
          nlohmann::json stats;
          master->ready_to_swap(*state, stats);
          // Frame 0 waits for the nodes to join: not a frame's cost.
          if (frame > 0 && frame < frames) frame_ms.push_back(ms_between(start, Clock::now()));
          for (const nlohmann::json& dropped : stats["cluster"]["dropped"])
            row.secondary_loss_ms = dropped["waited_ms"];
        }
        const Clock::time_point silent = Clock::now();
        silence_cluster_master(*master);
        for (std::thread& thread : secondaries) thread.join();
        for (int k = 1; k < nodes; ++k)
          if (k != silent_node)
            row.master_loss_ms =
                std::max(row.master_loss_ms, ms_between(silent, gave_up[std::size_t(k)]));
      }
      row.median_ms = percentile(frame_ms, 0.5);
      row.p99_ms = percentile(frame_ms, 0.99);
      row.worst_ms = percentile(frame_ms, 1.0);
      char line[200];
      std::snprintf(line, sizeof line,
                    "cluster %s %d nodes: %.3f ms median, %.3f ms p99, %.3f ms worst per frame; "
                    "lost secondary dropped after %.1f ms, lost master seen after %.1f ms",
                    transport.c_str(), nodes, row.median_ms, row.p99_ms, row.worst_ms,
                    row.secondary_loss_ms, row.master_loss_ms);
      if (progress) progress(line);
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace facet::driver
