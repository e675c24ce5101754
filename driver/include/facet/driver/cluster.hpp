#pragma once
// Clusters: one session over many render nodes (display.json "cluster"), frame-locked over NNG
// (nanomsg-next-generation's scalability protocols).
//
// Everything is pub/sub. The master owns the frame state. Every frame it
//   1. publishes FrameState N, together with the digest of the display and scene it runs; every
//      node renders its own projectors from it;
//   2. waits up to the cluster's deadline (its own timer, from when its own outputs are
//      rendered) for every node to say "frame N rendered", which each node publishes unasked on a
//      pub socket of its own, which the master subscribes to, from the thread that rendered, once
//      its outputs are rendered and about to swap;
//   3. publishes "swap N" with the nodes that missed the deadline, which are dropped from the
//      barrier, and the nodes that answered again, which rejoin it. Then every node swaps.
// Joining is the same exchange: the master asks "joined?" every 100 ms until every node answered
// or the join timeout passed.
// Whenever it has published nothing for a quarter deadline, the master publishes a heartbeat, so
// that a secondary that hears nothing for a deadline knows the master is gone, whatever the
// frames cost to render.
//
// Addresses: every node listens on its address (frame states, swaps and "joined?": a sub socket)
// and on cluster_barrier_address(address) (its answers: a pub socket); the master dials both of
// every other node, so nodes may start in any order, and a restarted node is found again by the
// master's dialers.
//
// No hardware swap lock: GLX_NV_swap_group is not used; the barrier is the software one above.
//
// No GL here: the wire format and the protocol run in any process.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "facet/driver/log.hpp"
#include "facet/driver/session.hpp"
#include "facet/projection_io/display_config.hpp"

namespace facet::driver {

// ---- Frame state on the wire ----------------------------------------------------------------

// "FSTA", a version, then every FrameState field, little-endian. A decoder refuses any other
// version: nodes of one cluster run the same facet.
inline constexpr std::uint16_t kFrameStateWireVersion = 1;

std::vector<std::uint8_t> encode_frame_state(const FrameState& state);
// Throws InputError(source, field, ...) for a wrong magic or version, a truncated or overlong
// message, a non-finite number or more than kMaxObjectPoses object poses.
FrameState decode_frame_state(std::span<const std::uint8_t> bytes, const std::string& source);

// 64-bit FNV-1a: the digest of a frame state (of its encoding) and of a display and scene.
class Digest {
 public:
  Digest& add(std::span<const std::uint8_t> bytes);
  Digest& add(std::string_view text);  // its bytes, then its length, so that "ab","c" != "a","bc"
  // The bytes of a file; InputError when it cannot be read.
  Digest& add_file(const std::filesystem::path& path);
  std::uint64_t value() const { return value_; }

 private:
  std::uint64_t value_ = 0xcbf29ce484222325ull;
};
std::string digest_hex(std::uint64_t digest);  // 16 lower-case hex digits
std::uint64_t frame_state_digest(const FrameState& state);

// What a display and a scene come to, for the master and its nodes to compare: display.json's
// bytes and those of every warp, blend and black file it names, the scene's name (and the bytes
// of its file), and `settings`: whatever else changes the pictures (the command line's --scale,
// --method, ...).
std::uint64_t content_digest(const projection_io::DisplayConfig& display,
                             const std::filesystem::path& display_file,
                             const std::string& scene_name,
                             const std::optional<std::filesystem::path>& scene_file,
                             const std::string& settings);

// ---- A node of a running cluster --------------------------------------------------------------

struct ClusterNodeOptions {
  projection_io::DisplayCluster cluster;
  std::string source;  // display.json, for messages
  std::string node;    // this process's node: one of cluster.nodes
  double frame_period_s = 1.0 / 60.0;
  std::uint64_t content_digest = 0;
  // How long the master waits for every node to join before it starts (a critical node that
  // has not joined by then stops it with PeerLost; the others may join later), and how long a
  // secondary waits for the first word from the master.
  std::chrono::milliseconds join_timeout{60'000};
  // Master: at most this many frames a second (a headless run paced like a show); nullopt: as
  // fast as the slowest node renders.
  std::optional<double> rate_hz;
  std::function<void(const std::string&)> report;  // one line per event; empty: none
};

// The cluster's deadline in ms: its deadline_ms, or kDefaultClusterDeadlineFrames frame periods.
double cluster_deadline_ms(const projection_io::DisplayCluster& cluster, double frame_period_s);

// The node named `node`, or InputError(source, OptionName "node", the names there are).
const projection_io::ClusterNode& find_cluster_node(const projection_io::DisplayCluster& cluster,
                                                    const std::string& node,
                                                    const std::string& source);

// Where a headless or windowed run gets its frames and when it may show them: frame-locked with
// a cluster.
class FrameSync {
 public:
  virtual ~FrameSync() = default;
  // The state to render next, given `own`: the state this process would show on its own (its
  // camera path or navigation at its next frame number). The master broadcasts `own` and
  // returns it; a secondary returns the newest state the master sent instead. nullopt when the
  // master says the run is over.
  virtual std::optional<FrameState> next_frame(const FrameState& own) = 0;
  // Called when `state`'s outputs are rendered: waits for the cluster, then says whether to show
  // (swap, write) them. Adds what it knows to `stats` (the frame's stats.jsonl line).
  virtual bool ready_to_swap(const FrameState& state, nlohmann::json& stats) = 0;
};

// The master: broadcasts the frame states and runs the barrier. Construction listens on the
// node's address and dials the others (InputError when the address cannot be listened on, e.g.
// in use); the first next_frame waits for the nodes to join. Loss of a critical node: PeerLost
// naming it, after telling every node to stop. The destructor tells the nodes the run is over.
std::unique_ptr<FrameSync> make_cluster_master(const ClusterNodeOptions& options);

// A secondary: listens on its addresses (InputError when it cannot) and renders what the master
// sends. PeerLost when the master has been silent for the deadline (or for join_timeout before
// its first word) or stops the cluster; InputError when the master runs another display or scene
// (a different content digest).
std::unique_ptr<FrameSync> make_cluster_secondary(const ClusterNodeOptions& options);

// For tests and benchmarks: the master (make_cluster_master's) stops speaking, heartbeat and
// end of run included, as if its process had died.
void silence_cluster_master(FrameSync& master);

// ---- Benchmark --------------------------------------------------------------------------------

// facet bench --scenario cluster: a master and nodes-1 secondaries on threads of one process,
// rendering nothing, over ipc:// or tcp:// on the loopback.
struct ClusterBenchOptions {
  std::vector<int> node_counts = {2, 4, 8};
  std::vector<std::string> transports = {"ipc", "tcp"};
  int frames = 600;
  double deadline_ms = 50;       // 3 frame periods at 60 Hz, the default
  std::filesystem::path folder;  // for ipc:// sockets; must exist
};
struct ClusterBenchRow {
  int nodes = 0;
  std::string transport;
  // Per frame, as the master sees it: broadcast, then the barrier until every node answered.
  double median_ms = 0, p99_ms = 0, worst_ms = 0;
  double secondary_loss_ms = 0;  // a secondary falls silent: the master's wait until it drops it
  double master_loss_ms = 0;     // the master falls silent: until the last secondary gives up
  // The floor under the protocol, measured before it on the same transport and node count:
  // NNG's exchange alone, per frame: the master publishes a frame state, each node answers it at
  // once on its own pub socket from a thread of its own, the master's sub socket
  // collects the answers; floor_expired frames whose deadline passed before every node answered
  // (not timed).
  double floor_median_ms = 0, floor_p99_ms = 0;
  int floor_expired = 0;
  // Timed frames the master swapped without every secondary in the barrier (one that did not
  // join, or was dropped): a row with any is not the protocol's cost at `nodes` nodes.
  int frames_short = 0;
};
// One row per node count and transport; `progress` gets a line per row.
std::vector<ClusterBenchRow> bench_cluster(const ClusterBenchOptions& options,
                                           const std::function<void(const std::string&)>& progress);

// A node's part of a display: takes the cluster section of `display_file` (a display.json) from
// display.config (load_session_display's result for the same file; read from the file only when
// `display` has none) and keeps in `display` the outputs of node `node`'s projectors only.
// InputError when the file has no cluster section or no such node.
struct ClusterNodeShare {
  projection_io::DisplayConfig config;
  std::string node;
  bool master = false;
};
ClusterNodeShare keep_cluster_node_outputs(SessionDisplay& display,
                                           const std::filesystem::path& display_file,
                                           const std::string& node);

// ---- The display a session or playback runs on, as one node or alone ------------------------

// What `facet run` and `facet play` ask of a cluster.
struct ClusterRequest {
  std::string node;               // this process's node; "" when not part of a cluster
  bool frames_given = false;      // a frame count was asked for (only the master's ends a run)
  std::optional<double> rate_hz;  // the master's pace, frames per second in (0, 10000]
  double join_timeout_s = 60;     // in (0, 86400]
};

struct NodeDisplay {
  SessionDisplay display;
  std::optional<ClusterNodeShare> cluster;  // set when the request names a node
};

// load_session_display(display, size), then scale_session_display(scale) when a scale is given,
// then, for a cluster node, its own outputs only (keep_cluster_node_outputs). InputError naming
// the flag for a node of a display that is not a display.json (--node), a frame count (--frames)
// or a rate (--rate) on a secondary node, a rate without a node or out of range, and a join
// timeout out of range (--join-timeout).
NodeDisplay load_node_display(const std::string& display, std::optional<glm::ivec2> size,
                              std::optional<double> scale, const ClusterRequest& request);

// Joins `share`'s cluster as its master or a secondary (make_cluster_master,
// make_cluster_secondary) at kFramePeriod_s, with the request's timeout and pace and the
// content_digest of what this node shows. The node's lines (who joined, missed a barrier, was
// dropped or rejoined) go to `log` as warnings.
std::unique_ptr<FrameSync> join_cluster(const ClusterNodeShare& share, const std::string& display,
                                        const ClusterRequest& request, std::uint64_t content_digest,
                                        const LogSink& log);

}  // namespace facet::driver
