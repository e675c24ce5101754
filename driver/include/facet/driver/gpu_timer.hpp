#pragma once
// Per-pass GPU timings from GL_TIME_ELAPSED queries, read back frames later so that timing never
// stalls the pipeline. On a software rasterizer (is_software_renderer) the queries do not time the
// work (llvmpipe's report seconds for a millisecond's pass), so there each pass is timed by the
// wall clock between a glFinish at its begin and one at its end: the CPU is the GPU there, and a
// pass's time is the time its work takes.
//
//   GpuTimer timer;
//   { auto t = timer.scope("pass1 coverage"); ... }   // or begin("...") / end()
//   { auto t = timer.scope("pass3 draw"); ... }
//   timer.end_frame();
//   while (auto frame = timer.poll()) report(*frame);   // frames come out in order
//
// GL allows one GL_TIME_ELAPSED query at a time, so passes must not nest (asserted).
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "facet/driver/gl_objects.hpp"

namespace facet::driver {

struct PassTime {
  std::string pass;
  double milliseconds = 0;  // GPU time between the pass's begin and end
};

class GpuTimer {
 public:
  enum class Clock {
    automatic,   // queries on a GPU, the wall clock on a software rasterizer
    queries,     // GL_TIME_ELAPSED
    wall_clock,  // glFinish, then the wall clock, at each begin and end
    // glFinish, then the CPU time of every thread of the process: on a software rasterizer the
    // work a pass costs, whatever else the machine runs. `automatic` takes it on a software
    // rasterizer when the environment sets FACET_PASS_CLOCK=cpu.
    process_cpu_time,
  };
  explicit GpuTimer(Clock clock = Clock::automatic);
  GpuTimer(GpuTimer&&) noexcept = default;
  GpuTimer& operator=(GpuTimer&&) noexcept = default;

  // Starts timing a pass. Needs a current context; no other pass of this timer may be open.
  void begin(std::string_view pass);
  void end();

  class Scope {
   public:
    explicit Scope(GpuTimer& timer) : timer_(&timer) {}
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;
    ~Scope() { timer_->end(); }

   private:
    GpuTimer* timer_;
  };
  // begin(pass) now, end() when the returned object goes out of scope.
  [[nodiscard]] Scope scope(std::string_view pass) {
    begin(pass);
    return Scope(*this);
  }

  // Closes the passes recorded since the last end_frame() into one frame.
  void end_frame();
  // The oldest closed frame's timings once all its queries are done (immediately with
  // wait = true, which blocks on the GPU), or nullopt when none is ready.
  std::optional<std::vector<PassTime>> poll(bool wait = false);
  // Frames closed but not yet returned by poll().
  std::size_t pending_frames() const { return frames_.size(); }

  // The GPU clock now, in nanoseconds (GL_TIMESTAMP; only differences mean anything).
  static std::int64_t timestamp_ns();

 private:
  struct Pending {
    std::string pass;
    Query query;              // queries only
    double milliseconds = 0;  // wall clock only, set by end()
  };
  bool wall_clock_ = false;  // wall_clock or process_cpu_time
  bool cpu_time_ = false;    // process_cpu_time
  std::int64_t wall_begin_ns_ = 0;
  std::vector<Pending> open_frame_;
  std::deque<std::vector<Pending>> frames_;
  std::vector<Query> free_;  // finished queries, reused instead of recreated
  bool in_pass_ = false;
};

}  // namespace facet::driver
