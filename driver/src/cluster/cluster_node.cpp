// The cluster protocol over NNG: the master's frame-state broadcast and swap barrier, and the
// secondaries' side of both, all over pub/sub. The master publishes frame states, swaps and the
// question "joined?" on one pub socket; every secondary says "frame N rendered" and answers
// "joined?" on a pub socket of its own, at its barrier address, which the master's one sub socket
// dials. The master's deadline is its own timer. See cluster.hpp.
//
// No surveyor/respondent: NNG 1.5.2's respondent keeps a closed surveyor pipe in its list of pipes
// to receive from and later uses it freed (nanomsg/nng#1959, fixed in NNG 1.10), which aborted a
// secondary whose master was killed ("panic: pthread_mutex_unlock: Invalid argument").
#include <nng/nng.h>
#include <nng/protocol/pubsub0/pub.h>
#include <nng/protocol/pubsub0/sub.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <tuple>

#include "facet/driver/cluster.hpp"
#include "facet/driver/session_runner.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"

namespace facet::driver {

using Clock = std::chrono::steady_clock;
using projection_io::ClusterNode;

double cluster_deadline_ms(const projection_io::DisplayCluster& cluster, double frame_period_s) {
  return cluster.deadline_ms.value_or(projection_io::kDefaultClusterDeadlineFrames *
                                      frame_period_s * 1000.0);
}

const ClusterNode& find_cluster_node(const projection_io::DisplayCluster& cluster,
                                     const std::string& node, const std::string& source) {
  std::string names;
  for (const ClusterNode& candidate : cluster.nodes) {
    if (candidate.name == node) return candidate;
    names += (names.empty() ? "" : ", ") + candidate.name;
  }
  throw InputError(source, OptionName{"node"},
                   "the name of one of the cluster's nodes (" + names + "), got '" + node + "'");
}

namespace {

// Message kinds. Every message the master publishes starts with its kind and its content digest.
// join is the question "joined?", followed by the frame number 0. A secondary publishes on its
// own pub socket a kind and a frame number, its content digest and its name: join and 0 to
// answer the question, ready and N once its outputs of frame N are rendered, unasked: frame N's
// state is the question.
constexpr std::chrono::milliseconds kRefusedNodeAnswersFor{1000};

enum class Published : std::uint8_t {
  heartbeat = 1,
  frame = 2,
  swap = 3,
  end = 4,
  stop = 5,
  join = 6,
  ready = 7
};

constexpr auto kCloseWait = std::chrono::seconds(2);  // Socket::close

Clock::duration period(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string ms_text(double ms) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f ms", ms);
  return text;
}

class Bytes {
 public:
  template <typename T>
  Bytes& put(const T& value) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    data.insert(data.end(), p, p + sizeof value);
    return *this;
  }
  Bytes& put_bytes(std::span<const std::uint8_t> bytes) {
    data.insert(data.end(), bytes.begin(), bytes.end());
    return *this;
  }
  Bytes& put_text(std::string_view text) {
    return put_bytes(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  }
  std::vector<std::uint8_t> data;
};

// Reads a received message front to back; `ok` turns false on a short message.
class Parse {
 public:
  explicit Parse(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  template <typename T>
  T get() {
    T value{};
    if (bytes_.size() - at_ < sizeof value) {
      ok = false;
      return value;
    }
    std::memcpy(&value, bytes_.data() + at_, sizeof value);
    at_ += sizeof value;
    return value;
  }
  std::span<const std::uint8_t> rest() const { return bytes_.subspan(at_); }
  std::string rest_text() const {
    return std::string(reinterpret_cast<const char*>(bytes_.data() + at_), bytes_.size() - at_);
  }
  bool ok = true;

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
};

// "cluster.nodes[K].address" of node `node`, as display.json's reader names it.
std::string address_field(const projection_io::DisplayCluster& cluster, const std::string& node) {
  for (std::size_t k = 0; k < cluster.nodes.size(); ++k)
    if (cluster.nodes[k].name == node) return "cluster.nodes[" + std::to_string(k) + "].address";
  return "cluster.nodes";
}

// One NNG socket, closed with its owner.
class Socket {
 public:
  Socket() = default;
  ~Socket() { close(); }
  // Closes it now; a receive blocked on it returns at once.
  // NNG 1.5.2 can deadlock in nng_close while a peer's pipe is going away (nanomsg/nng#1543 and
  // #1813; seen here in about 1 of 50 secondaries stopping): the close runs on a thread of its
  // own, and after kCloseWait the socket is left to it, and to the process's exit, which NNG does
  // not hold up (it has no exit handler). False then.
  bool close() {
    if (!open_) return true;
    open_ = false;
    auto closed = std::make_shared<std::promise<void>>();
    std::future<void> done = closed->get_future();
    std::thread([socket = socket_, closed] {
      nng_close(socket);
      closed->set_value();
    }).detach();
    return done.wait_for(kCloseWait) == std::future_status::ready;
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;

  void open(int (*opener)(nng_socket*), const char* what) {
    if (const int error = opener(&socket_))
      throw std::runtime_error(std::string("cannot open an NNG ") + what +
                               " socket: " + nng_strerror(error));
    open_ = true;
  }
  nng_socket get() const { return socket_; }

  // Listens on `address`; InputError naming the node and the address when it cannot (in use,
  // no such local address, a path that cannot be made).
  // `peer` opens the protocol that dials this socket (pub for a sub): an ipc:// address is
  // dialled with it first, since NNG, finding the path in use, probes it with a bare connection
  // that leaves the listener there deaf.
  void listen(const std::string& address, const std::string& source, const std::string& field,
              const std::string& node, int (*peer)(nng_socket*)) {
    if (address.starts_with("ipc://")) {
      nng_socket probe = NNG_SOCKET_INITIALIZER;
      if (peer(&probe) == 0) {
        const int dialled = nng_dial(probe, address.c_str(), nullptr, 0);
        nng_close(probe);
        if (dialled == 0)
          throw InputError(source, field,
                           "an address node '" + node + "' can listen on, but " + address +
                               ": another process listens there (is node '" + node +
                               "' running twice?)");
      }
    }
    if (const int error = nng_listen(socket_, address.c_str(), nullptr, 0)) {
      std::string why = nng_strerror(error);
      if (error == NNG_EADDRINUSE)
        why += ": another process listens there (is node '" + node + "' running twice?)";
      throw InputError(source, field,
                       "an address node '" + node + "' can listen on, but " + address + ": " + why);
    }
  }
  // Dials `address` in the background, again and again until it answers and whenever it is lost.
  void dial(const std::string& address) {
    const int error = nng_dial(socket_, address.c_str(), nullptr, NNG_FLAG_NONBLOCK);
    if (error != 0) throw std::runtime_error("cannot dial " + address + ": " + nng_strerror(error));
  }
  void set_ms(const char* option, double ms) {
    nng_socket_set_ms(socket_, option, nng_duration(std::max(1.0, std::ceil(ms))));
  }
  void send(const std::vector<std::uint8_t>& bytes) {
    // A pub socket never blocks: a message for no subscriber, or for one whose queue is full, is
    // dropped by NNG.
    nng_send(socket_, const_cast<std::uint8_t*>(bytes.data()), bytes.size(), 0);
  }
  // A message, or nullopt after the receive timeout (or any other error).
  std::optional<std::vector<std::uint8_t>> receive(int* error_out = nullptr) {
    void* buffer = nullptr;
    std::size_t size = 0;
    const int error = nng_recv(socket_, &buffer, &size, NNG_FLAG_ALLOC);
    if (error_out) *error_out = error;
    if (error != 0) return std::nullopt;
    const auto* p = static_cast<const std::uint8_t*>(buffer);
    std::vector<std::uint8_t> bytes(p, p + size);
    nng_free(buffer, size);
    return bytes;
  }

 private:
  nng_socket socket_ = NNG_SOCKET_INITIALIZER;
  bool open_ = false;
};

// An empty ClusterNodeOptions::report says nothing.
void report_nowhere(const std::string&) {}

void say_no_swap_group_once(const std::function<void(const std::string&)>& report) {
  static std::once_flag said;
  std::call_once(said, [&] {
    report(
        "no hardware swap lock (GLX_NV_swap_group is not used): frames are locked by the "
        "software barrier");
  });
}

// One node's part in a frame's barrier, as the master saw it.
struct Dropped {
  std::string node;
  std::uint64_t frame = 0;
  double waited_ms = 0;
};

nlohmann::json swap_json(std::uint64_t frame, const std::vector<Dropped>& dropped,
                         const std::vector<std::string>& rejoined,
                         const std::vector<std::string>& active) {
  nlohmann::json dropped_json = nlohmann::json::array();
  for (const Dropped& d : dropped)
    dropped_json.push_back({{"node", d.node}, {"frame", d.frame}, {"waited_ms", d.waited_ms}});
  return {{"frame", frame}, {"dropped", dropped_json}, {"rejoined", rejoined}, {"active", active}};
}

// ---- Master ------------------------------------------------------------------------------------

class Master final : public FrameSync {
 public:
  explicit Master(const ClusterNodeOptions& options)
      : options_(options),
        deadline_ms_(cluster_deadline_ms(options.cluster, options.frame_period_s)) {
    if (!options_.report) options_.report = report_nowhere;
    const ClusterNode& self = find_cluster_node(options_.cluster, options_.node, options_.source);
    publisher_.open(nng_pub0_open, "pub");
    answers_.open(nng_sub0_open, "sub");
    nng_socket_set(answers_.get(), NNG_OPT_SUB_SUBSCRIBE, "", 0);
    nng_socket_set_int(answers_.get(), NNG_OPT_RECVBUF, 1024);
    const std::string field = address_field(options_.cluster, self.name);
    publisher_.listen(self.address, options_.source, field, self.name, nng_sub0_open);
    // Nothing dials the master's barrier address; it is held all the same, as every node holds
    // its own, so that every node's two addresses are in use while it runs.
    answers_.listen(projection_io::cluster_barrier_address(self.address), options_.source, field,
                    self.name, nng_pub0_open);
    for (Socket* socket : {&publisher_, &answers_}) {
      socket->set_ms(NNG_OPT_RECONNMINT, 10);
      socket->set_ms(NNG_OPT_RECONNMAXT, 100);
    }
    for (const ClusterNode& node : options_.cluster.nodes) {
      if (node.name == self.name) continue;
      publisher_.dial(node.address);
      answers_.dial(projection_io::cluster_barrier_address(node.address));
      secondaries_.push_back(&node);
    }
    say_no_swap_group_once(options_.report);
    heartbeat_ = std::thread([this] { beat(); });
  }

  ~Master() override {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    heartbeat_.join();
    // Said a few times: a subscriber that is reconnecting must not miss the end and wait for a
    // deadline instead.
    if (!stopped_) {
      for (int i = 0; i < 3; ++i) {
        publish(Published::end, Bytes().put(last_frame_).data);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // let the last words go out
  }

  std::optional<FrameState> next_frame(const FrameState& own) override {
    if (!joined_) wait_for_nodes();
    if (options_.rate_hz) {
      // A frame period after the last frame began, or at once when that has passed (after a
      // wait for a lost node): a late cluster goes on at its pace, it does not rush to catch up.
      if (frames_sent_ > 0)
        std::this_thread::sleep_until(last_start_ + period(1 / *options_.rate_hz));
      last_start_ = Clock::now();
    }
    ++frames_sent_;
    last_frame_ = own.frame;
    const FrameState& state = own;
    const Clock::time_point start = Clock::now();
    publish(Published::frame, encode_frame_state(state));
    last_broadcast_ms_ = ms_since(start);
    return state;
  }

  void fall_silent() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    heartbeat_.join();
    heartbeat_ = std::thread([] {});
    stopped_ = true;
  }

  bool ready_to_swap(const FrameState& state, nlohmann::json& stats) override {
    const Clock::time_point start = Clock::now();
    // Rounded up: waited_ms, reported for a dropped node, is never below the deadline.
    const Clock::time_point deadline =
        start +
        std::chrono::ceil<Clock::duration>(std::chrono::duration<double, std::milli>(deadline_ms_));
    // A node says "rendered" once it has rendered the frame state published in next_frame: it
    // heard the state. Earlier frames' words wait in the queue and are passed over.
    std::set<std::string> answered;
    std::vector<std::string> rejoined;
    while (answered.size() < active_.size() + rejoined.size()) {
      const auto reply = receive_answer(deadline);
      if (!reply) break;  // the deadline has passed
      const auto answer = parse_answer(*reply, Published::ready, state.frame);
      if (!answer) continue;
      if (active_.contains(*answer) ||
          std::find(rejoined.begin(), rejoined.end(), *answer) != rejoined.end()) {
        answered.insert(*answer);
      } else {
        rejoined.push_back(*answer);
        answered.insert(*answer);
      }
    }
    const double barrier_ms = ms_since(start);
    std::vector<Dropped> dropped;
    for (const std::string& node : active_) {
      if (!answered.contains(node)) dropped.push_back({node, state.frame, barrier_ms});
    }
    for (const Dropped& d : dropped) {
      active_.erase(d.node);
      options_.report("node " + d.node + " missed the barrier of frame " + std::to_string(d.frame) +
                      ": no answer within " + ms_text(d.waited_ms) + "; dropped, the others go on");
    }
    for (const std::string& node : rejoined) {
      active_.insert(node);
      options_.report("node " + node + " rejoined at frame " + std::to_string(state.frame));
    }
    for (const Dropped& d : dropped) {
      if (node_named(d.node).critical) {
        const std::string reason = "critical node " + d.node + " lost at frame " +
                                   std::to_string(d.frame) + " (no answer within " +
                                   ms_text(d.waited_ms) + ")";
        stop(reason);
        throw PeerLost(reason);
      }
    }
    const std::vector<std::string> active(active_.begin(), active_.end());
    const nlohmann::json swap = swap_json(state.frame, dropped, rejoined, active);
    const Clock::time_point release = Clock::now();
    publish(Published::swap, Bytes().put(state.frame).put_text(swap.dump()).data);
    const double release_ms = ms_since(release);
    nlohmann::json cluster = swap;
    cluster["node"] = options_.node;
    cluster["role"] = "master";
    cluster["state_digest"] = digest_hex(frame_state_digest(state));
    cluster["barrier_ms"] = barrier_ms;
    cluster["broadcast_ms"] = last_broadcast_ms_ + release_ms;
    cluster["swapped"] = true;
    stats["cluster"] = std::move(cluster);
    return true;
  }

 private:
  void publish(Published kind, const std::vector<std::uint8_t>& body) {
    publisher_.send(Bytes().put(kind).put(options_.content_digest).put_bytes(body).data);
    last_published_.store(Clock::now().time_since_epoch().count(), std::memory_order_relaxed);
  }

  void stop(const std::string& reason) {
    stopped_ = true;
    for (int i = 0; i < 3; ++i) {
      publish(Published::stop, Bytes().put_text(reason).data);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  const ClusterNode& node_named(const std::string& name) const {
    return find_cluster_node(options_.cluster, name, options_.source);
  }

  // The next answer a secondary published, or nullopt once `deadline` has passed. NNG's timeout
  // is whole milliseconds on a clock of its own: one that ends a little early is waited again,
  // so that nobody is declared lost before the deadline.
  std::optional<std::vector<std::uint8_t>> receive_answer(Clock::time_point deadline) {
    for (;;) {
      const double left =
          std::chrono::duration<double, std::milli>(deadline - Clock::now()).count();
      if (left <= 0) return std::nullopt;
      answers_.set_ms(NNG_OPT_RECVTIMEO, left);
      int error = 0;
      std::optional<std::vector<std::uint8_t>> answer = answers_.receive(&error);
      if (answer || error != NNG_ETIMEDOUT) return answer;
    }
  }

  // The node that said `kind` for `frame` (join for 0: it heard "joined?"; ready for N: it
  // rendered frame N's state), when it runs our display and scene; the others are reported once
  // each and ignored. Words about other frames (an earlier frame's, said after its deadline) are
  // ignored. A node that says either heard every message published before what it answers: it
  // needs no more to join.
  std::optional<std::string> parse_answer(const std::vector<std::uint8_t>& reply, Published kind,
                                          std::uint64_t frame) {
    Parse in(reply);
    const auto answer_kind = in.get<Published>();
    const auto answer_frame = in.get<std::uint64_t>();
    const auto digest = in.get<std::uint64_t>();
    const std::string name = in.rest_text();
    if (!in.ok || answer_kind != kind || answer_frame != frame) return std::nullopt;
    const bool known = std::any_of(secondaries_.begin(), secondaries_.end(),
                                   [&](const ClusterNode* node) { return node->name == name; });
    if (!known) {
      if (complained_.insert("unknown " + name).second)
        options_.report("an answer from '" + name + "', which is no secondary of " +
                        options_.source + "; ignored");
      return std::nullopt;
    }
    if (digest != options_.content_digest) {
      refused_.insert(name);
      if (complained_.insert("digest " + name).second)
        options_.report("node " + name + " runs another display or scene (content digest " +
                        digest_hex(digest) + ", the master's " +
                        digest_hex(options_.content_digest) + "): refused");
      return std::nullopt;
    }
    return name;
  }

  void wait_for_nodes() {
    joined_ = true;
    const Clock::time_point start = Clock::now();
    std::string names;
    for (const ClusterNode* node : secondaries_) names += " " + node->name;
    if (!secondaries_.empty())
      options_.report("master " + options_.node + ": waiting up to " +
                      ms_text(double(options_.join_timeout.count())) + " for nodes" + names);
    // A node refused for its content digest runs another display or scene: it will not join
    // before it is restarted, so the wait ends once every other node has joined.
    const auto waiting = [this] {
      return std::any_of(secondaries_.begin(), secondaries_.end(), [this](const ClusterNode* n) {
        return !active_.contains(n->name) && !refused_.contains(n->name);
      });
    };
    while (waiting() && Clock::now() - start < options_.join_timeout) {
      if (const int signal = interrupt_signal())
        throw Interrupted(signal, "stopped while waiting for the cluster's nodes");
      // Asked again every 100 ms: a node that has just come, or whose answer socket the master
      // has not reached yet, answers the next one. The question is also the sign of life.
      publish(Published::join, Bytes().put(std::uint64_t(0)).data);
      const Clock::time_point next_ask = Clock::now() + std::chrono::milliseconds(100);
      while (waiting()) {
        const auto reply = receive_answer(next_ask);
        if (!reply) break;
        if (const auto name = parse_answer(*reply, Published::join, 0)) {
          active_.insert(*name);
          refused_.erase(*name);
        }
      }
    }
    std::string missing, refused;
    for (const ClusterNode* node : secondaries_) {
      if (active_.contains(node->name)) continue;
      const bool was_refused = refused_.contains(node->name);
      (was_refused ? refused : missing) += " " + node->name;
      if (!node->critical) continue;
      const std::string reason =
          "critical node " + node->name +
          (was_refused ? " runs another display or scene"
                       : " did not join within " + ms_text(double(options_.join_timeout.count())));
      stop(reason);
      throw PeerLost(reason);
    }
    if (!missing.empty())
      options_.report("starting without" + missing + " (not joined within " +
                      ms_text(double(options_.join_timeout.count())) + "; they join when ready)");
    if (!refused.empty())
      options_.report("starting without" + refused +
                      " (refused: another display or scene; restarted with this one, they join)");
    if (missing.empty() && refused.empty() && !secondaries_.empty())
      options_.report("all " + std::to_string(secondaries_.size() + 1) + " nodes joined in " +
                      ms_text(ms_since(start)) + "; deadline " + ms_text(deadline_ms_));
  }

  // A heartbeat when nothing else was published for a quarter deadline: while frames follow
  // each other faster than that, they are the sign of life, and a heartbeat would only wake every
  // node in the middle of a barrier.
  void beat() {
    const Clock::duration every = period(std::max(1.0, deadline_ms_ / 4) / 1000);
    std::unique_lock lock(mutex_);
    while (!stopping_) {
      const Clock::time_point last{
          Clock::duration(last_published_.load(std::memory_order_relaxed))};
      const Clock::time_point now = Clock::now();
      if (now - last >= every) {
        publish(Published::heartbeat, {});
        wake_.wait_for(lock, every, [this] { return stopping_; });
      } else {
        wake_.wait_until(lock, last + every, [this] { return stopping_; });
      }
    }
  }

  ClusterNodeOptions options_;
  double deadline_ms_;
  // Main thread: both; heartbeat thread: publisher_, until the destructor has joined it.
  Socket publisher_, answers_;
  std::vector<const ClusterNode*> secondaries_;
  std::set<std::string> active_;   // secondaries in the barrier
  std::set<std::string> refused_;  // secondaries that answered with another content digest
  std::set<std::string> complained_;
  bool joined_ = false, stopped_ = false;
  std::uint64_t frames_sent_ = 0, last_frame_ = 0;
  double last_broadcast_ms_ = 0;
  Clock::time_point last_start_;
  std::atomic<Clock::rep> last_published_{0};  // when anything was last published
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread heartbeat_;
};

// ---- Secondary ---------------------------------------------------------------------------------

class Secondary final : public FrameSync {
 public:
  explicit Secondary(const ClusterNodeOptions& options)
      : options_(options),
        deadline_ms_(cluster_deadline_ms(options.cluster, options.frame_period_s)),
        self_(find_cluster_node(options_.cluster, options_.node, options_.source)),
        master_(options_.cluster.master) {
    if (!options_.report) options_.report = report_nowhere;
    subscriber_.open(nng_sub0_open, "sub");
    answers_.open(nng_pub0_open, "pub");
    nng_socket_set(subscriber_.get(), NNG_OPT_SUB_SUBSCRIBE, "", 0);
    nng_socket_set_int(subscriber_.get(), NNG_OPT_RECVBUF, 1024);
    const std::string field = address_field(options_.cluster, self_.name);
    subscriber_.listen(self_.address, options_.source, field, self_.name, nng_pub0_open);
    answers_.listen(projection_io::cluster_barrier_address(self_.address), options_.source, field,
                    self_.name, nng_sub0_open);
    say_no_swap_group_once(options_.report);
    options_.report("node " + self_.name + ": listening on " + self_.address + " for master " +
                    master_);
    if (const int error = nng_aio_alloc(&receiving_, on_received, this))
      throw std::runtime_error(std::string("cannot make an NNG aio: ") + nng_strerror(error));
    nng_aio_set_timeout(receiving_, NNG_DURATION_INFINITE);
    nng_recv_aio(subscriber_.get(), receiving_);
  }

  // Receiving stops first (nng_aio_stop waits for a running callback), then the sockets close:
  // nothing uses a socket after its close.
  ~Secondary() override {
    nng_aio_stop(receiving_);
    nng_aio_free(receiving_);
    for (Socket* socket : {&subscriber_, &answers_}) {
      if (!socket->close())
        options_.report("node " + self_.name +
                        ": an NNG socket did not close within 2 s (an NNG 1.5.2 deadlock); left "
                        "to the process's exit");
    }
  }

  std::optional<FrameState> next_frame(const FrameState&) override {
    std::unique_lock lock(mutex_);
    for (;;) {
      check(lock);
      // The newest frame state wins: a node that fell behind catches up at once.
      std::optional<std::vector<std::uint8_t>> newest;
      bool ended = false;
      while (!inbox_.empty()) {
        auto [kind, body] = std::move(inbox_.front());
        inbox_.pop_front();
        if (kind == Published::frame) newest = std::move(body);
        if (kind == Published::end) ended = true;
      }
      if (ended) return std::nullopt;
      if (newest) {
        FrameState state = decode_frame_state(*newest, "frame state from master " + master_);
        if (rendered_ && state.frame <= *rendered_) continue;  // old news
        return state;
      }
      wait(lock);
    }
  }

  bool ready_to_swap(const FrameState& state, nlohmann::json& stats) override {
    // Said from this thread as soon as the outputs are rendered: no question to wait for, no
    // other thread to wake.
    answer(Published::ready, state.frame);
    std::unique_lock lock(mutex_);
    rendered_ = state.frame;
    for (;;) {
      check(lock);
      while (!inbox_.empty()) {
        auto& [kind, body] = inbox_.front();
        if (kind == Published::frame || kind == Published::end) {
          // The master went on without this frame (it was dropped, or fell behind): not shown.
          record(stats, state, false, nlohmann::json());
          return false;
        }
        if (kind == Published::swap) {
          Parse in(body);
          const auto frame = in.get<std::uint64_t>();
          if (in.ok && frame == state.frame) {
            nlohmann::json swap = nlohmann::json::parse(in.rest_text(), nullptr, false);
            inbox_.pop_front();
            report_swap(swap);
            record(stats, state, true, swap);
            return true;
          }
        }
        inbox_.pop_front();
      }
      wait(lock);
    }
  }

 private:
  void record(nlohmann::json& stats, const FrameState& state, bool swapped,
              const nlohmann::json& swap) {
    nlohmann::json cluster = {{"node", self_.name},
                              {"role", "secondary"},
                              {"frame", state.frame},
                              {"state_digest", digest_hex(frame_state_digest(state))},
                              {"swapped", swapped}};
    if (swap.is_object()) {
      for (const char* key : {"dropped", "rejoined", "active"})
        if (swap.contains(key)) cluster[key] = swap[key];
    }
    stats["cluster"] = std::move(cluster);
  }

  void report_swap(const nlohmann::json& swap) {
    if (!swap.is_object()) return;
    for (const nlohmann::json& d : swap.value("dropped", nlohmann::json::array()))
      options_.report("master " + master_ + " dropped node " + d.value("node", "?") + " at frame " +
                      std::to_string(d.value("frame", std::uint64_t(0))) + " (no answer within " +
                      ms_text(d.value("waited_ms", 0.0)) + ")");
    for (const nlohmann::json& node : swap.value("rejoined", nlohmann::json::array()))
      options_.report("node " + node.get<std::string>() + " rejoined");
  }

  // Throws for what the receive callback has seen: the master's stop, another display, silence.
  void check(std::unique_lock<std::mutex>& lock) {
    if (const int signal = interrupt_signal())
      throw Interrupted(signal, "stopped as a node of the cluster");
    if (!stop_reason_.empty()) throw PeerLost("master " + master_ + " stopped: " + stop_reason_);
    if (foreign_digest_) {
      // A node of another display answers the master's "joined?" for a while before it stops
      // (the receive callback answers), so that the master hears its digest, reports the
      // refusal and stops waiting for it: NNG drops what is published before the master's
      // subscription has connected. It takes no frame meanwhile.
      inbox_changed_.wait_until(lock, foreign_since_ + kRefusedNodeAnswersFor, [this] {
        return Clock::now() >= foreign_since_ + kRefusedNodeAnswersFor;
      });
      throw InputError(options_.source, "cluster",
                       "the display and scene master " + master_ + " runs (content digest " +
                           digest_hex(*foreign_digest_) + "), but this node's differ (" +
                           digest_hex(options_.content_digest) +
                           "): run the same display.json, warps, blends, scene and options on "
                           "every node");
    }
    if (!last_heard_) {
      if (ms_since(started_) > double(options_.join_timeout.count()))
        throw PeerLost("master " + master_ + " not heard from within " +
                       ms_text(double(options_.join_timeout.count())) + " of the start");
    } else if (const double silent = ms_since(*last_heard_); silent > deadline_ms_) {
      throw PeerLost("master " + master_ + " lost: silent for " + ms_text(silent) + " (deadline " +
                     ms_text(deadline_ms_) + ")");
    }
  }

  // Until something arrives, or at most 5 ms, or the moment the master's silence would pass the
  // deadline, so that check() sees the loss on time.
  void wait(std::unique_lock<std::mutex>& lock) {
    Clock::time_point until = Clock::now() + std::chrono::milliseconds(5);
    if (last_heard_)
      until = std::min(until,
                       *last_heard_ + period(deadline_ms_ / 1000) + std::chrono::microseconds(100));
    inbox_changed_.wait_until(lock, until);
  }

  // NNG's callback for a message on subscriber_ (or an error), on one of NNG's own threads:
  // the message is taken in there, so that nothing but the thread it is for wakes.
  static void on_received(void* self) { static_cast<Secondary*>(self)->received(); }
  void received() {
    const int error = nng_aio_result(receiving_);
    if (error == NNG_ECANCELED || error == NNG_ECLOSED) return;  // stopping
    if (error == 0) {
      nng_msg* message = nng_aio_get_msg(receiving_);
      take(
          std::span(static_cast<const std::uint8_t*>(nng_msg_body(message)), nng_msg_len(message)));
      nng_msg_free(message);
    }
    nng_recv_aio(subscriber_.get(), receiving_);
  }

  void take(std::span<const std::uint8_t> message) {
    Parse in(message);
    const auto kind = in.get<Published>();
    const auto digest = in.get<std::uint64_t>();
    if (!in.ok) return;
    std::lock_guard lock(mutex_);
    last_heard_ = Clock::now();
    if (digest != options_.content_digest) {
      if (!foreign_digest_) foreign_since_ = Clock::now();
      foreign_digest_ = digest;
    }
    if (kind == Published::stop) stop_reason_ = in.rest_text();
    if (kind == Published::join) {
      // Answered here at once; the main thread waits for frame states and swaps only.
      if (in.get<std::uint64_t>() == 0 && in.ok) answer(Published::join, 0);
      if (foreign_digest_) inbox_changed_.notify_one();
    } else if (kind != Published::heartbeat) {
      inbox_.emplace_back(kind, std::vector<std::uint8_t>(in.rest().begin(), in.rest().end()));
      inbox_changed_.notify_one();
    } else if (foreign_digest_) {
      inbox_changed_.notify_one();
    }
    // A plain heartbeat wakes nobody: it moves last_heard_, which check() reads when the main
    // thread wakes, at the latest when the old silence would have passed the deadline.
  }

  // On this node's own pub socket: the receive callback answers "joined?", the main thread says
  // "rendered" (NNG sockets may be shared between threads).
  void answer(Published kind, std::uint64_t frame) {
    answers_.send(
        Bytes().put(kind).put(frame).put(options_.content_digest).put_text(self_.name).data);
  }

  ClusterNodeOptions options_;
  double deadline_ms_;
  const ClusterNode& self_;
  std::string master_;
  // receiving_ takes subscriber_'s messages; its callback and the main thread send on answers_;
  // both close after receiving has stopped.
  Socket subscriber_, answers_;
  nng_aio* receiving_ = nullptr;
  std::mutex mutex_;
  // The main thread waits for the inbox (and the master's silence).
  std::condition_variable inbox_changed_;
  std::deque<std::pair<Published, std::vector<std::uint8_t>>> inbox_;
  std::optional<Clock::time_point> last_heard_;
  Clock::time_point started_ = Clock::now();
  std::optional<std::uint64_t> rendered_;
  std::optional<std::uint64_t> foreign_digest_;
  Clock::time_point foreign_since_;
  std::string stop_reason_;
};

}  // namespace

std::unique_ptr<FrameSync> make_cluster_master(const ClusterNodeOptions& options) {
  return std::make_unique<Master>(options);
}

ClusterNodeShare keep_cluster_node_outputs(SessionDisplay& display,
                                           const std::filesystem::path& display_file,
                                           const std::string& node) {
  ClusterNodeShare share;
  share.config =
      display.config ? *display.config : projection_io::read_display_config(display_file);
  if (!share.config.cluster)
    throw InputError(display_file.string(), "cluster",
                     "a cluster section for a cluster node (nodes, their projectors and the "
                     "master)");
  const ClusterNode& self = find_cluster_node(*share.config.cluster, node, display_file.string());
  share.node = self.name;
  share.master = share.config.cluster->master == self.name;
  std::vector<SessionOutput> kept;
  for (std::size_t i = 0; i < share.config.projectors.size() && i < display.outputs.size(); ++i) {
    const std::vector<std::string>& mine = self.projectors;
    if (std::find(mine.begin(), mine.end(), share.config.projectors[i].name) != mine.end())
      kept.push_back(std::move(display.outputs[i]));
  }
  display.outputs = std::move(kept);
  return share;
}

NodeDisplay load_node_display(const std::string& display, std::optional<glm::ivec2> size,
                              std::optional<double> scale, const ClusterRequest& request) {
  NodeDisplay loaded{load_session_display(display, size), std::nullopt};
  if (scale) scale_session_display(loaded.display, *scale);
  if (!request.node.empty()) {
    if (!display.ends_with(".json"))
      throw InputError("command line", OptionName{"node"}, "a display.json with a cluster section");
    loaded.cluster = keep_cluster_node_outputs(loaded.display, display, request.node);
    if (!loaded.cluster->master && request.frames_given)
      throw InputError("command line", OptionName{"frames"},
                       "none on a secondary node: the master's frame count ends the run on "
                       "every node");
    if (!loaded.cluster->master && request.rate_hz)
      throw InputError("command line", OptionName{"rate_hz"},
                       "none on a secondary node: the master paces");
    if (!(request.join_timeout_s > 0 && request.join_timeout_s <= 86400))
      throw InputError("command line", OptionName{"join_timeout_s"}, "seconds in (0, 86400]");
  } else if (request.rate_hz) {
    throw InputError("command line", OptionName{"rate_hz"},
                     "only on a cluster's master node, which it paces");
  }
  if (request.rate_hz && !(*request.rate_hz > 0 && *request.rate_hz <= 10000))
    throw InputError("command line", OptionName{"rate_hz"}, "frames per second in (0, 10000]");
  return loaded;
}

std::unique_ptr<FrameSync> join_cluster(const ClusterNodeShare& share, const std::string& display,
                                        const ClusterRequest& request, std::uint64_t content_digest,
                                        const LogSink& log) {
  FACET_ASSERT(share.config.cluster);
  ClusterNodeOptions options;
  options.cluster = *share.config.cluster;
  options.source = display;
  options.node = share.node;
  options.frame_period_s = kFramePeriod_s;
  options.join_timeout = std::chrono::milliseconds(std::int64_t(request.join_timeout_s * 1000));
  options.rate_hz = request.rate_hz;
  options.content_digest = content_digest;
  if (log) options.report = [log](const std::string& line) { log(LogLevel::warning, line); };
  return share.master ? make_cluster_master(options) : make_cluster_secondary(options);
}

std::unique_ptr<FrameSync> make_cluster_secondary(const ClusterNodeOptions& options) {
  return std::make_unique<Secondary>(options);
}

void silence_cluster_master(FrameSync& master) {
  if (auto* m = dynamic_cast<Master*>(&master)) m->fall_silent();
}

}  // namespace facet::driver
