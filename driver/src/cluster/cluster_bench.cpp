// facet bench --scenario cluster: the cluster protocol's cost per frame and its loss detection,
// with nodes on threads that render nothing.
#include <netinet/in.h>
#include <nng/nng.h>
#include <nng/protocol/pubsub0/pub.h>
#include <nng/protocol/pubsub0/sub.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "facet/driver/cluster.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

// A socket bound to loopback TCP port `port` (0: the kernel's choice), or -1 when it cannot be.
int bind_loopback(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(std::uint16_t(port));
  if (fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) return fd;
  if (fd >= 0) ::close(fd);
  return -1;
}

int bound_port(int fd) {
  sockaddr_in address{};
  socklen_t size = sizeof address;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) return 0;
  return ntohs(address.sin_port);
}

// Loopback TCP ports P and P + 1 (a node's address and its barrier) that nobody holds now, held
// in `held` (closed by the caller once every node has its pair, so that no two nodes share a
// port). Both are checked: Linux hands out odd ports to bind() and even ones to connect(), so the
// port after the kernel's choice is one that outgoing connections use.
int free_loopback_port_pair(std::vector<int>& held) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int first = bind_loopback(0);
    if (first < 0) continue;
    const int port = bound_port(first);
    const int second = port > 0 && port < 65534 ? bind_loopback(port + 1) : -1;
    if (second >= 0) {
      held.push_back(first);
      held.push_back(second);
      return port;
    }
    ::close(first);
  }
  throw std::runtime_error("cluster bench: no two free loopback TCP ports in a row");
}

projection_io::DisplayCluster bench_cluster_config(int nodes, const std::string& transport,
                                                   const std::filesystem::path& folder,
                                                   double deadline_ms) {
  projection_io::DisplayCluster cluster;
  std::vector<int> held;  // the ports chosen so far, until every node has its pair
  struct Closer {
    std::vector<int>& fds;
    ~Closer() {
      for (const int fd : fds) ::close(fd);
    }
  } closer{held};
  for (int k = 0; k < nodes; ++k) {
    const std::string name = "n" + std::to_string(k);
    std::string address;
    if (transport == "tcp") {
      // Two ports each: the barrier listens on the next one.
      address = "tcp://127.0.0.1:" + std::to_string(free_loopback_port_pair(held));
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

// The floor under the protocol: NNG's own exchange, the one the protocol makes, on the same
// transport between the same number of nodes. Per frame the master publishes a message of
// `state_bytes`; every other node, on a thread of its own, receives it from its sub socket and
// answers at once on a pub socket of its own, which
// the master's one sub socket dials; the master waits for every answer, until the deadline by its
// own clock. None of facet's protocol: no heartbeat, no hand-off between threads, no swap message,
// no digests. Sets row.floor_*.
void bench_bare_nng(const projection_io::DisplayCluster& cluster, int frames,
                    std::size_t state_bytes, double deadline_ms, ClusterBenchRow& row) {
  auto check = [](int error, const char* what) {
    if (error != 0)
      throw std::runtime_error(std::string("bare NNG bench: ") + what + ": " + nng_strerror(error));
  };
  const std::size_t nodes = cluster.nodes.size();
  // Every socket is closed on the way out, thrown or not, after the threads that use them have
  // ended; the threads start once all listen.
  std::vector<nng_socket> sockets;
  struct Closer {
    std::vector<nng_socket>& sockets;
    ~Closer() {
      for (nng_socket socket : sockets) nng_close(socket);
    }
  } closer{sockets};
  auto open = [&](int (*opener)(nng_socket*), const char* what) {
    nng_socket socket = NNG_SOCKET_INITIALIZER;
    check(opener(&socket), what);
    sockets.push_back(socket);
    return socket;
  };
  const nng_socket publisher = open(nng_pub0_open, "pub");
  const nng_socket answers = open(nng_sub0_open, "sub");
  check(nng_socket_set(answers, NNG_OPT_SUB_SUBSCRIBE, "", 0), "subscribe");
  std::vector<std::pair<nng_socket, nng_socket>> node_sockets;  // subscriber, answering publisher
  for (std::size_t k = 1; k < nodes; ++k) {
    const std::string& address = cluster.nodes[k].address;
    const std::string barrier = projection_io::cluster_barrier_address(address);
    const nng_socket subscriber = open(nng_sub0_open, "sub");
    const nng_socket answerer = open(nng_pub0_open, "pub");
    node_sockets.emplace_back(subscriber, answerer);
    check(nng_socket_set(subscriber, NNG_OPT_SUB_SUBSCRIBE, "", 0), "subscribe");
    check(nng_socket_set_ms(subscriber, NNG_OPT_RECVTIMEO, 20), "timeout");
    check(nng_listen(subscriber, address.c_str(), nullptr, 0), address.c_str());
    check(nng_listen(answerer, barrier.c_str(), nullptr, 0), barrier.c_str());
    check(nng_dial(publisher, address.c_str(), nullptr, NNG_FLAG_NONBLOCK), address.c_str());
    check(nng_dial(answers, barrier.c_str(), nullptr, NNG_FLAG_NONBLOCK), barrier.c_str());
  }
  // A message is a kind byte (1: frame state, 2: answer) and a frame number, then (for a frame
  // state) the frame state's bytes.
  constexpr std::uint8_t kState = 1, kAnswer = 2;
  constexpr std::size_t kHeader = 1 + sizeof(std::uint64_t);
  std::atomic<bool> stop{false};
  std::vector<std::thread> threads;
  for (const auto& [subscriber, answerer] : node_sockets) {
    // Each frame state is answered with its kind byte and frame number.
    threads.emplace_back([subscriber = subscriber, answerer = answerer, &stop] {
      while (!stop.load()) {
        void* message = nullptr;
        std::size_t size = 0;
        if (nng_recv(subscriber, &message, &size, NNG_FLAG_ALLOC) != 0) continue;
        if (size < kHeader) {
          nng_free(message, size);
          continue;
        }
        const bool is_state = *static_cast<const std::uint8_t*>(message) == kState;
        std::uint8_t answer[kHeader] = {kAnswer};
        std::memcpy(answer + 1, static_cast<const std::uint8_t*>(message) + 1,
                    sizeof(std::uint64_t));
        nng_free(message, size);
        if (is_state) nng_send(answerer, answer, sizeof answer, 0);
      }
    });
  }
  std::vector<std::uint8_t> state(std::max(state_bytes, kHeader), 0);
  // One exchange: the time until every node answered, or nullopt when the deadline passed first.
  auto exchange = [&](std::uint64_t frame) -> std::optional<double> {
    const Clock::time_point start = Clock::now();
    const Clock::time_point deadline =
        start + std::chrono::duration_cast<Clock::duration>(
                    std::chrono::duration<double, std::milli>(deadline_ms));
    state[0] = kState;
    std::memcpy(state.data() + 1, &frame, sizeof frame);
    nng_send(publisher, state.data(), state.size(), 0);
    for (std::size_t answered = 0; answered + 1 < nodes;) {
      const double left =
          std::chrono::duration<double, std::milli>(deadline - Clock::now()).count();
      if (left <= 0) return std::nullopt;
      nng_socket_set_ms(answers, NNG_OPT_RECVTIMEO, nng_duration(std::ceil(left)));
      void* answer = nullptr;
      std::size_t size = 0;
      const int error = nng_recv(answers, &answer, &size, NNG_FLAG_ALLOC);
      if (error == NNG_ETIMEDOUT) continue;
      if (error != 0) return std::nullopt;
      std::uint64_t answered_frame = 0;
      if (size == kHeader) std::memcpy(&answered_frame, static_cast<std::uint8_t*>(answer) + 1, 8);
      nng_free(answer, size);
      if (answered_frame == frame) ++answered;
    }
    return ms_between(start, Clock::now());
  };
  // Until every node is connected and answers (at most 30 s), then the frames timed.
  std::uint64_t frame = 1;
  const Clock::time_point joining = Clock::now();
  int in_a_row = 0;
  while (in_a_row < 10 && Clock::now() - joining < std::chrono::seconds(30))
    in_a_row = exchange(frame++) ? in_a_row + 1 : 0;
  std::vector<double> frame_ms;
  int expired = 0;
  for (int i = 0; i < frames && in_a_row == 10; ++i) {
    if (const std::optional<double> ms = exchange(frame++))
      frame_ms.push_back(*ms);
    else
      ++expired;
  }
  stop = true;
  for (std::thread& thread : threads) thread.join();
  if (in_a_row < 10) throw std::runtime_error("bare NNG bench: the nodes did not connect in 30 s");
  row.floor_median_ms = percentile(frame_ms, 0.5);
  row.floor_p99_ms = percentile(frame_ms, 0.99);
  row.floor_expired = expired;
}

}  // namespace

std::vector<ClusterBenchRow> bench_cluster(
    const ClusterBenchOptions& options, const std::function<void(const std::string&)>& progress) {
  if (options.frames < 10)
    throw InputError("command line", OptionName{"frames"}, "at least 10 frames");
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
      if (nodes >= 2) {
        if (transport == "ipc") std::filesystem::create_directories(options.folder / "bare");
        FrameState typical;
        typical.frame = 1000;
        // A port the kernel offered may be taken by the time it is listened on (and the barrier
        // listens on the next one): then again with other ports, three times at most.
        for (int attempt = 1;; ++attempt) {
          try {
            bench_bare_nng(bench_cluster_config(nodes, transport, options.folder / "bare",
                                                options.deadline_ms),
                           options.frames, encode_frame_state(typical).size() + 9,
                           options.deadline_ms, row);
            break;
          } catch (const std::runtime_error&) {
            if (attempt == 3) throw;
          }
        }
      }
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
          if (frame > 0 && frame < frames) {
            frame_ms.push_back(ms_between(start, Clock::now()));
            // A timed frame swapped without every secondary: its time is not the protocol's.
            if (stats["cluster"]["active"].size() + 1 < std::size_t(nodes)) ++row.frames_short;
          }
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
      char line[400];
      std::snprintf(
          line, sizeof line,
          "cluster %s %d nodes: %.3f ms median, %.3f ms p99, %.3f ms worst per frame; "
          "lost secondary dropped after %.1f ms, lost master seen after %.1f ms; "
          "bare NNG publish+answers %.3f ms median, %.3f ms p99%s",
          transport.c_str(), nodes, row.median_ms, row.p99_ms, row.worst_ms, row.secondary_loss_ms,
          row.master_loss_ms, row.floor_median_ms, row.floor_p99_ms,
          row.frames_short > 0 ? ("; NOT COMPARABLE: " + std::to_string(row.frames_short) +
                                  " timed frames without every node in the barrier")
                                     .c_str()
                               : "");
      if (progress) progress(line);
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace facet::driver
