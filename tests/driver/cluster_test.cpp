// Clusters without GL: the frame state's wire format, and the protocol (broadcast, barrier,
// drop, rejoin, loss of the master, a foreign display, an address in use) between a master and
// secondaries on threads of this process, over ipc://.
#include "facet/driver/cluster.hpp"

#include <gtest/gtest.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "facet/projection/errors.hpp"
#include "support/files.hpp"

namespace facet::driver {
namespace {

namespace fs = std::filesystem;
namespace pio = facet::projection_io;

// Every field filled with random values, object poses included.
FrameState random_state(std::mt19937_64& random) {
  std::uniform_real_distribution<double> number(-1e3, 1e3);
  auto matrix = [&] {
    glm::dmat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = number(random);
    return m;
  };
  FrameState state;
  state.frame = random();
  state.time_s = number(random);
  state.T_world_eye = matrix();
  state.object_poses.resize(random() % 6);
  for (ObjectPose& pose : state.object_poses) {
    pose.object = std::uint32_t(random());
    pose.T_world_object = matrix();
  }
  return state;
}

std::string decode_error(const std::vector<std::uint8_t>& bytes) {
  try {
    decode_frame_state(bytes, "wire");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ClusterWire, FrameStatesRoundTripBitForBit) {
  std::mt19937_64 random(15);
  for (int i = 0; i < 200; ++i) {
    const FrameState state = random_state(random);
    const std::vector<std::uint8_t> bytes = encode_frame_state(state);
    EXPECT_EQ(bytes.size(), 4 + 2 + 8 + 8 + 128 + 4 + state.object_poses.size() * (4 + 128));
    EXPECT_EQ(decode_frame_state(bytes, "wire"), state) << "state " << i;
    EXPECT_EQ(frame_state_digest(decode_frame_state(bytes, "wire")), frame_state_digest(state));
  }
  // Each field shows in the digest.
  std::mt19937_64 again(16);
  const FrameState state = random_state(again);
  FrameState changed = state;
  changed.frame += 1;
  EXPECT_NE(frame_state_digest(changed), frame_state_digest(state));
  changed = state;
  changed.time_s = std::nextafter(state.time_s, 1e9);
  EXPECT_NE(frame_state_digest(changed), frame_state_digest(state));
  changed = state;
  changed.T_world_eye[2][1] += 1e-9;
  EXPECT_NE(frame_state_digest(changed), frame_state_digest(state));
  changed = state;
  changed.object_poses.push_back(ObjectPose{});
  EXPECT_NE(frame_state_digest(changed), frame_state_digest(state));
}

TEST(ClusterWire, BadMessagesAreRefusedWithTheirField) {
  std::mt19937_64 random(17);
  FrameState state = random_state(random);
  state.object_poses.resize(2);
  const std::vector<std::uint8_t> good = encode_frame_state(state);
  // Cut anywhere: refused, never read past the end.
  for (std::size_t size = 0; size < good.size(); ++size) {
    const std::vector<std::uint8_t> cut(good.begin(), good.begin() + std::ptrdiff_t(size));
    EXPECT_NE(decode_error(cut), "no error") << size;
  }
  std::vector<std::uint8_t> bytes = good;
  bytes[4] = 2;  // version 2
  EXPECT_NE(decode_error(bytes).find("field 'version': frame state version 1"), std::string::npos)
      << decode_error(bytes);
  bytes = good;
  bytes[0] = 'X';
  EXPECT_NE(decode_error(bytes).find("field 'magic'"), std::string::npos);
  bytes = good;
  bytes.push_back(0);
  EXPECT_NE(decode_error(bytes).find("1 more bytes follow"), std::string::npos);
  // A pose count far beyond what the message holds is refused before any allocation.
  bytes = good;
  const std::size_t count_at = 4 + 2 + 8 + 8 + 128;
  bytes[count_at + 3] = 0x7f;
  EXPECT_NE(decode_error(bytes).find("field 'object_poses'"), std::string::npos);
  // Not a number.
  bytes = good;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(bytes.data() + 4 + 2 + 8, &nan, sizeof nan);
  EXPECT_NE(decode_error(bytes).find("field 'time_s'"), std::string::npos);
}

TEST(ClusterWire, DigestsTellContentsApart) {
  EXPECT_NE(Digest().add("ab").add("c").value(), Digest().add("a").add("bc").value());
  EXPECT_EQ(Digest().add("abc").value(), Digest().add("abc").value());
  EXPECT_EQ(digest_hex(0x1234), "0000000000001234");
}

// ---- The display of one node --------------------------------------------------------------

// load_node_display: a node keeps its own projectors at the asked scale; the flags that make no
// sense for its role, or for no cluster, are refused by name.
TEST(NodeDisplay, ANodeKeepsItsProjectorsAndItsRoleIsChecked) {
  const facet::test::TempFolder temp("facet-node-display");
  const fs::path& folder = temp.path();
  write_session_display(load_session_display("builtin:wall2x2", glm::ivec2(64, 40)), "wall",
                        folder / "wall");
  const fs::path json = folder / "wall" / "display.json";
  pio::DisplayConfig config = pio::read_display_config(json);
  ASSERT_EQ(config.projectors.size(), 4u);
  pio::DisplayCluster cluster;
  cluster.nodes.push_back(
      {"a", "tcp://127.0.0.1:7400", {config.projectors[0].name, config.projectors[1].name}, true});
  cluster.nodes.push_back(
      {"b", "tcp://127.0.0.1:7410", {config.projectors[2].name, config.projectors[3].name}, false});
  cluster.master = "a";
  config.cluster = cluster;
  fs::remove(json);
  pio::write_display_config(config, json);

  auto field_of = [&](const std::string& display, const ClusterRequest& request) {
    try {
      load_node_display(display, std::nullopt, std::nullopt, request);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  EXPECT_EQ(field_of("builtin:wall2x2", {"a", false, std::nullopt, 60}), "node");
  EXPECT_EQ(field_of("builtin:wall2x2", {"", false, 30.0, 60}), "rate_hz");
  EXPECT_EQ(field_of(json.string(), {"b", true, std::nullopt, 60}), "frames");
  EXPECT_EQ(field_of(json.string(), {"b", false, 30.0, 60}), "rate_hz");
  EXPECT_EQ(field_of(json.string(), {"a", false, 0.0, 60}), "rate_hz");
  EXPECT_EQ(field_of(json.string(), {"a", false, std::nullopt, 0}), "join_timeout_s");

  const NodeDisplay secondary =
      load_node_display(json.string(), std::nullopt, 0.5, {"b", false, std::nullopt, 5});
  ASSERT_TRUE(secondary.cluster);
  EXPECT_FALSE(secondary.cluster->master);
  ASSERT_EQ(secondary.display.outputs.size(), 2u);
  EXPECT_EQ(secondary.display.outputs[0].spec.name, config.projectors[2].name);
  EXPECT_EQ(secondary.display.outputs[1].spec.warp.output_size, glm::ivec2(32, 20));
  const NodeDisplay master =
      load_node_display(json.string(), std::nullopt, std::nullopt, {"a", true, 30.0, 60});
  ASSERT_TRUE(master.cluster);
  EXPECT_TRUE(master.cluster->master);
  EXPECT_EQ(master.display.outputs.size(), 2u);
  EXPECT_EQ(load_node_display(json.string(), std::nullopt, std::nullopt, {}).display.outputs.size(),
            4u);
}

// How often `path` is opened while `work` runs (inotify: an IN_OPEN event per open; closes are
// watched too, so that two opens in a row are not merged into one event).
template <typename Work>
int opens_of(const fs::path& path, Work work) {
  const int fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (fd < 0) return -1;
  if (inotify_add_watch(fd, path.c_str(), IN_OPEN | IN_CLOSE) < 0) {
    ::close(fd);
    return -1;
  }
  work();
  int opens = 0;
  alignas(inotify_event) char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n <= 0) break;
    for (ssize_t k = 0; k < n;) {
      const auto* event = reinterpret_cast<const inotify_event*>(buffer + k);
      opens += (event->mask & IN_OPEN) != 0;
      k += ssize_t(sizeof(inotify_event) + event->len);
    }
  }
  ::close(fd);
  return opens;
}

// A display.json is read once per run: for its outputs, render settings and blends, and for a
// cluster node's section (it was read twice, and three times for a node).
TEST(NodeDisplay, ADisplayJsonIsReadOnce) {
  const facet::test::TempFolder temp("facet-read-once");
  const fs::path& folder = temp.path();
  write_session_display(load_session_display("builtin:wall2x2", glm::ivec2(64, 40)), "wall",
                        folder / "wall");
  const fs::path json = folder / "wall" / "display.json";
  pio::DisplayConfig config = pio::read_display_config(json);
  pio::DisplayCluster cluster;
  cluster.nodes.push_back(
      {"a", "tcp://127.0.0.1:7400", {config.projectors[0].name, config.projectors[1].name}, true});
  cluster.nodes.push_back(
      {"b", "tcp://127.0.0.1:7410", {config.projectors[2].name, config.projectors[3].name}, false});
  cluster.master = "a";
  config.cluster = cluster;
  fs::remove(json);
  pio::write_display_config(config, json);

  // The counter sees a read of its own.
  EXPECT_EQ(opens_of(json, [&] { pio::read_display_config(json); }), 1);
  SessionDisplay display;
  EXPECT_EQ(opens_of(json, [&] { display = load_session_display(json.string()); }), 1);
  EXPECT_EQ(display.outputs.size(), 4u);
  ASSERT_TRUE(display.config);
  EXPECT_EQ(display.config->projectors.size(), 4u);
  NodeDisplay node;
  EXPECT_EQ(opens_of(json,
                     [&] {
                       node = load_node_display(json.string(), std::nullopt, std::nullopt,
                                                {"b", false, std::nullopt, 5});
                     }),
            1);
  ASSERT_TRUE(node.cluster);
  EXPECT_EQ(node.cluster->node, "b");
  ASSERT_TRUE(node.cluster->config.cluster);
  EXPECT_EQ(node.cluster->config.cluster->master, "a");
  EXPECT_EQ(node.display.outputs.size(), 2u);
}

// ---- The protocol, on threads -----------------------------------------------------------------

// Nodes a (master), b and c on ipc:// sockets in `folder`; c critical when asked.
pio::DisplayCluster test_cluster(const fs::path& folder, double deadline_ms,
                                 bool c_critical = false) {
  pio::DisplayCluster cluster;
  for (const char* name : {"a", "b", "c"})
    cluster.nodes.push_back({name,
                             "ipc://" + (folder / name).string(),
                             {std::string("p") + name},
                             std::string(name) == "c" && c_critical});
  cluster.master = "a";
  cluster.deadline_ms = deadline_ms;
  return cluster;
}

struct Log {
  std::mutex mutex;
  std::vector<std::string> lines;
  std::function<void(const std::string&)> sink(const std::string& who) {
    return [this, who](const std::string& line) {
      std::lock_guard lock(mutex);
      lines.push_back(who + ": " + line);
    };
  }
  bool contains(const std::string& text) {
    std::lock_guard lock(mutex);
    for (const std::string& line : lines)
      if (line.find(text) != std::string::npos) return true;
    return false;
  }
  std::string all() {
    std::lock_guard lock(mutex);
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    return text;
  }
};

ClusterNodeOptions node_options(const pio::DisplayCluster& cluster, const std::string& node,
                                Log& log, std::uint64_t digest = 42) {
  ClusterNodeOptions options;
  options.cluster = cluster;
  options.source = "display.json";
  options.node = node;
  options.content_digest = digest;
  options.join_timeout = std::chrono::milliseconds(20'000);
  options.report = log.sink(node);
  return options;
}

FrameState state_of(std::uint64_t frame) {
  FrameState state;
  state.frame = frame;
  state.time_s = double(frame) / 60;
  state.T_world_eye[3] = glm::dvec4(double(frame), 1.5, -2.0, 1.0);
  state.object_poses = {ObjectPose{std::uint32_t(frame % 3), glm::dmat4(2.0)}};
  return state;
}

// What one node did: per frame it rendered, the state digest and whether it swapped.
struct NodeRun {
  std::vector<std::uint64_t> swapped;
  std::vector<std::string> digests;
  std::vector<nlohmann::json> cluster_stats;
  std::string error;  // "PeerLost: ...", "InputError: ..."
};

// Runs a secondary until the master ends the run, or `stop_after` frames swapped (then it goes
// silent, as a killed process would).
NodeRun run_secondary(const ClusterNodeOptions& options,
                      std::optional<std::size_t> stop_after = std::nullopt) {
  NodeRun run;
  try {
    const std::unique_ptr<FrameSync> sync = make_cluster_secondary(options);
    while (const std::optional<FrameState> state = sync->next_frame(FrameState{})) {
      if (stop_after && run.swapped.size() >= *stop_after) break;
      nlohmann::json stats;
      if (sync->ready_to_swap(*state, stats)) {
        run.swapped.push_back(state->frame);
        run.digests.push_back(stats["cluster"]["state_digest"]);
        run.cluster_stats.push_back(stats["cluster"]);
      }
    }
  } catch (const PeerLost& e) {
    run.error = std::string("PeerLost: ") + e.what();
  } catch (const InputError& e) {
    run.error = std::string("InputError: ") + e.what();
  }
  return run;
}

NodeRun run_master(const ClusterNodeOptions& options, std::uint64_t frames,
                   std::chrono::milliseconds frame_time = std::chrono::milliseconds(2)) {
  NodeRun run;
  try {
    const std::unique_ptr<FrameSync> sync = make_cluster_master(options);
    for (std::uint64_t frame = 0; frame < frames; ++frame) {
      const std::optional<FrameState> state = sync->next_frame(state_of(frame));
      if (!state) break;
      std::this_thread::sleep_for(frame_time);  // "rendering"
      nlohmann::json stats;
      if (sync->ready_to_swap(*state, stats)) {
        run.swapped.push_back(state->frame);
        run.digests.push_back(stats["cluster"]["state_digest"]);
        run.cluster_stats.push_back(stats["cluster"]);
      }
    }
  } catch (const PeerLost& e) {
    run.error = std::string("PeerLost: ") + e.what();
  } catch (const InputError& e) {
    run.error = std::string("InputError: ") + e.what();
  }
  return run;
}

std::vector<std::uint64_t> frames_upto(std::uint64_t count) {
  std::vector<std::uint64_t> frames(count);
  for (std::uint64_t i = 0; i < count; ++i) frames[i] = i;
  return frames;
}

TEST(ClusterProtocol, EveryNodeSwapsEveryFrameWithTheSameState) {
  const facet::test::TempFolder scratch("facet-cluster-test");
  const pio::DisplayCluster cluster = test_cluster(scratch.path(), 2000);
  Log log;
  NodeRun b, c, a;
  std::thread tb([&] { b = run_secondary(node_options(cluster, "b", log)); });
  std::thread tc([&] { c = run_secondary(node_options(cluster, "c", log)); });
  a = run_master(node_options(cluster, "a", log), 40);
  tb.join();
  tc.join();
  EXPECT_EQ(a.error, "");
  EXPECT_EQ(b.error, "");
  EXPECT_EQ(c.error, "");
  EXPECT_EQ(a.swapped, frames_upto(40)) << log.all();
  EXPECT_EQ(b.swapped, a.swapped);
  EXPECT_EQ(c.swapped, a.swapped);
  EXPECT_EQ(b.digests, a.digests);
  EXPECT_EQ(c.digests, a.digests);
  EXPECT_EQ(a.digests[7], digest_hex(frame_state_digest(state_of(7))));
  for (const nlohmann::json& stats : a.cluster_stats) {
    EXPECT_EQ(stats["dropped"].size(), 0u);
    EXPECT_EQ(stats["active"], nlohmann::json({"b", "c"}));
  }
  std::vector<double> barrier_ms;
  for (const nlohmann::json& stats : a.cluster_stats) barrier_ms.push_back(stats["barrier_ms"]);
  std::sort(barrier_ms.begin(), barrier_ms.end());
  std::printf("barrier of 3 nodes: median %.3f ms, worst %.3f ms (not asserted)\n",
              barrier_ms[barrier_ms.size() / 2], barrier_ms.back());
}

TEST(ClusterProtocol, ASilentSecondaryIsDroppedAndRejoins) {
  const facet::test::TempFolder scratch("facet-cluster-test");
  const pio::DisplayCluster cluster = test_cluster(scratch.path(), 300);
  Log log;
  NodeRun b, c1, c2, a;
  std::atomic<bool> c_gone = false;
  std::thread tb([&] { b = run_secondary(node_options(cluster, "b", log)); });
  std::thread tc([&] {
    c1 = run_secondary(node_options(cluster, "c", log), 10);
    c_gone = true;
    c2 = run_secondary(node_options(cluster, "c", log));  // restarted
  });
  // Slow enough frames that the restarted c finds the run still going.
  a = run_master(node_options(cluster, "a", log), 80, std::chrono::milliseconds(10));
  tb.join();
  tc.join();
  EXPECT_EQ(a.error, "") << log.all();
  EXPECT_EQ(b.error, "");
  EXPECT_EQ(a.swapped, frames_upto(80)) << log.all();
  EXPECT_EQ(b.swapped, a.swapped);
  EXPECT_EQ(c1.swapped, frames_upto(10));
  // The master dropped c at one frame, said how long it waited, and took it back later.
  std::optional<std::uint64_t> dropped_at, rejoined_at;
  for (std::size_t i = 0; i < a.cluster_stats.size(); ++i) {
    const nlohmann::json& stats = a.cluster_stats[i];
    for (const nlohmann::json& d : stats["dropped"]) {
      EXPECT_EQ(d["node"], "c");
      EXPECT_GE(d["waited_ms"].get<double>(), 300.0 * 0.9);
      dropped_at = d["frame"].get<std::uint64_t>();
    }
    if (!stats["rejoined"].empty()) rejoined_at = a.swapped[i];
  }
  ASSERT_TRUE(dropped_at.has_value()) << log.all();
  ASSERT_TRUE(rejoined_at.has_value()) << log.all();
  EXPECT_GE(*dropped_at, 10u);
  EXPECT_GT(*rejoined_at, *dropped_at);
  EXPECT_TRUE(log.contains("a: node c missed the barrier of frame")) << log.all();
  // b heard of it from the master.
  EXPECT_TRUE(log.contains("b: master a dropped node c at frame")) << log.all();
  // The restarted c swapped every frame from its rejoining on, with the master's states.
  ASSERT_FALSE(c2.swapped.empty());
  EXPECT_LE(c2.swapped.front(), *rejoined_at);
  EXPECT_EQ(c2.swapped.back(), 79u);
  EXPECT_EQ(c2.swapped.size(), 80 - c2.swapped.front()) << "c missed frames after rejoining";
  for (std::size_t i = 0; i < c2.swapped.size(); ++i)
    EXPECT_EQ(c2.digests[i], a.digests[c2.swapped[i]]);
}

TEST(ClusterProtocol, LosingACriticalNodeStopsEveryone) {
  const facet::test::TempFolder scratch("facet-cluster-test");
  const pio::DisplayCluster cluster = test_cluster(scratch.path(), 300, true);
  Log log;
  NodeRun b, c, a;
  std::thread tb([&] { b = run_secondary(node_options(cluster, "b", log)); });
  std::thread tc([&] { c = run_secondary(node_options(cluster, "c", log), 5); });
  a = run_master(node_options(cluster, "a", log), 1000);
  tb.join();
  tc.join();
  EXPECT_NE(a.error.find("PeerLost: critical node c lost at frame"), std::string::npos) << a.error;
  EXPECT_NE(b.error.find("PeerLost: master a stopped: critical node c lost"), std::string::npos)
      << b.error;
  EXPECT_LT(a.swapped.size(), 1000u);
}

TEST(ClusterProtocol, ASecondaryWithoutAMasterGivesUp) {
  // A master that is killed mid-run is the CLI test's (cluster_cli_test.cpp); here none comes.
  const facet::test::TempFolder scratch("facet-cluster-test");
  const pio::DisplayCluster cluster = test_cluster(scratch.path(), 100);
  Log log;
  ClusterNodeOptions options = node_options(cluster, "b", log);
  options.join_timeout = std::chrono::milliseconds(300);
  const NodeRun b = run_secondary(options);
  EXPECT_NE(b.error.find("PeerLost: master a not heard from within 300.0 ms"), std::string::npos)
      << b.error;
}

// Master a runs 5 frames with b and with c, whose content digest (43) is another display's; c is
// critical when asked. The master's join timeout is 60 s: c's refusal must settle the wait.
struct RefusedNodeRuns {
  NodeRun a, b, c;
  Log log;
};
void run_with_a_refused_c(bool c_critical, RefusedNodeRuns& runs) {
  const facet::test::TempFolder scratch("facet-cluster-test");
  const pio::DisplayCluster cluster = test_cluster(scratch.path(), 300, c_critical);
  std::thread tb([&] { runs.b = run_secondary(node_options(cluster, "b", runs.log)); });
  std::thread tc([&] { runs.c = run_secondary(node_options(cluster, "c", runs.log, 43)); });
  ClusterNodeOptions master = node_options(cluster, "a", runs.log);
  master.join_timeout = std::chrono::milliseconds(60'000);
  runs.a = run_master(master, 5);
  tb.join();
  tc.join();
}

TEST(ClusterProtocol, ANodeOfAnotherDisplayIsRefused) {
  RefusedNodeRuns runs;
  run_with_a_refused_c(false, runs);
  EXPECT_FALSE(runs.log.contains("not joined within")) << runs.log.all();
  EXPECT_NE(runs.c.error.find("InputError: display.json: field 'cluster': the display and scene "
                              "master a runs (content digest 000000000000002a), but this node's "
                              "differ (000000000000002b)"),
            std::string::npos)
      << runs.c.error;
  EXPECT_TRUE(runs.log.contains("a: starting without c (refused: another display or scene"))
      << runs.log.all();
  // c is not critical: the others run without it.
  EXPECT_EQ(runs.a.error, "");
  EXPECT_EQ(runs.b.swapped, frames_upto(5));
}

TEST(ClusterProtocol, ARefusedCriticalNodeStopsEveryone) {
  RefusedNodeRuns runs;
  run_with_a_refused_c(true, runs);
  EXPECT_NE(runs.a.error.find("PeerLost: critical node c runs another display or scene"),
            std::string::npos)
      << runs.a.error << "\n"
      << runs.log.all();
  EXPECT_NE(runs.b.error.find("PeerLost: master a stopped: critical node c runs another display"),
            std::string::npos)
      << runs.b.error;
  EXPECT_TRUE(runs.a.swapped.empty());
}

TEST(ClusterProtocol, AnAddressInUseIsAnInputError) {
  const facet::test::TempFolder scratch("facet-cluster-test");
  const pio::DisplayCluster cluster = test_cluster(scratch.path(), 300);
  Log log;
  const std::unique_ptr<FrameSync> first = make_cluster_secondary(node_options(cluster, "b", log));
  try {
    make_cluster_secondary(node_options(cluster, "b", log));
    ADD_FAILURE() << "a second node b listened too";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is node 'b' running twice?"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(find_cluster_node(cluster, "d", "display.json"), InputError);
}

TEST(ClusterBench, ReportsEveryNodeCountAndBothLosses) {
  const facet::test::TempFolder scratch("facet-cluster-test");
  ClusterBenchOptions options;
  options.node_counts = {2, 3};
  options.frames = 20;
  options.folder = scratch.path();
  std::vector<std::string> lines;
  const std::vector<ClusterBenchRow> rows =
      bench_cluster(options, [&](const std::string& line) { lines.push_back(line); });
  ASSERT_EQ(rows.size(), 4u);  // ipc and tcp, 2 and 3 nodes
  EXPECT_EQ(lines.size(), 4u);
  for (const ClusterBenchRow& row : rows) {
    EXPECT_GT(row.median_ms, 0) << row.transport << " " << row.nodes;
    EXPECT_LE(row.median_ms, row.p99_ms);
    // NNG's own exchange on the same transport, measured before the protocol.
    EXPECT_GT(row.floor_median_ms, 0) << row.transport << " " << row.nodes;
    EXPECT_LE(row.floor_median_ms, row.floor_p99_ms);
    // Nobody is declared lost before the deadline has passed (the master's own timer, from the
    // start of the barrier); the 2-node row has no secondary to lose besides the one the master
    // needs.
    if (row.nodes == 3) {
      EXPECT_GE(row.secondary_loss_ms, options.deadline_ms);
    }
    EXPECT_GE(row.master_loss_ms, options.deadline_ms * 0.5);
  }
}

// join_cluster gives the node's lines to the caller's log sink, as warnings (the CLI prints
// them on stderr after "facet run: "); without a sink the node says nothing.
TEST(ClusterProtocol, JoinClusterReportsToTheLogSink) {
  const facet::test::TempFolder scratch("facet-cluster-test");
  ClusterNodeShare share;
  share.config.cluster = test_cluster(scratch.path(), 300);
  share.node = "b";
  std::vector<std::pair<LogLevel, std::string>> lines;
  const LogSink log = [&lines](LogLevel level, const std::string& line) {
    lines.emplace_back(level, line);
  };
  join_cluster(share, "display.json", ClusterRequest{}, 42, log).reset();
  const std::string listening =
      "node b: listening on ipc://" + (scratch.path() / "b").string() + " for master a";
  const auto line = std::find_if(lines.begin(), lines.end(),
                                 [&](const auto& l) { return l.second == listening; });
  ASSERT_NE(line, lines.end()) << lines.size() << " lines";
  EXPECT_EQ(line->first, LogLevel::warning);
  for (const auto& [level, text] : lines) EXPECT_EQ(level, LogLevel::warning) << text;
}

}  // namespace
}  // namespace facet::driver
