#include "facet/driver/gpu_timer.hpp"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <string_view>

#include "facet/driver/gpu_scene.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::int64_t process_cpu_ns() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return std::int64_t(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

bool cpu_clock_wanted() {
  const char* value = std::getenv("FACET_PASS_CLOCK");
  return value && std::string_view(value) == "cpu";
}

std::int64_t now_ns(bool cpu_time) { return cpu_time ? process_cpu_ns() : steady_ns(); }

}  // namespace

GpuTimer::GpuTimer(Clock clock) {
  if (clock == Clock::automatic && is_software_renderer())
    clock = cpu_clock_wanted() ? Clock::process_cpu_time : Clock::wall_clock;
  wall_clock_ = clock == Clock::wall_clock || clock == Clock::process_cpu_time;
  cpu_time_ = clock == Clock::process_cpu_time;
}

void GpuTimer::begin(std::string_view pass) {
  FACET_ASSERT(!in_pass_);
  in_pass_ = true;
  if (wall_clock_) {
    glFinish();
    open_frame_.push_back({std::string(pass), Query{}, 0});
    wall_begin_ns_ = now_ns(cpu_time_);
    return;
  }
  Query query;
  if (!free_.empty()) {
    query = std::move(free_.back());
    free_.pop_back();
  } else {
    query = Query::create(GL_TIME_ELAPSED);
  }
  glBeginQuery(GL_TIME_ELAPSED, query.id());
  open_frame_.push_back({std::string(pass), std::move(query), 0});
}

void GpuTimer::end() {
  FACET_ASSERT(in_pass_);
  in_pass_ = false;
  if (wall_clock_) {
    glFinish();
    open_frame_.back().milliseconds = double(now_ns(cpu_time_) - wall_begin_ns_) * 1e-6;
    return;
  }
  glEndQuery(GL_TIME_ELAPSED);
}

void GpuTimer::end_frame() {
  FACET_ASSERT(!in_pass_);
  frames_.push_back(std::move(open_frame_));
  open_frame_.clear();
}

std::optional<std::vector<PassTime>> GpuTimer::poll(bool wait) {
  if (frames_.empty()) return std::nullopt;
  auto& frame = frames_.front();
  if (!wait && !wall_clock_)
    for (const auto& pending : frame)
      if (!pending.query.available()) return std::nullopt;
  std::vector<PassTime> times;
  times.reserve(frame.size());
  for (auto& pending : frame) {
    if (wall_clock_) {
      times.push_back({std::move(pending.pass), pending.milliseconds});
      continue;
    }
    times.push_back({std::move(pending.pass), static_cast<double>(pending.query.result()) * 1e-6});
    free_.push_back(std::move(pending.query));
  }
  frames_.pop_front();
  return times;
}

std::int64_t GpuTimer::timestamp_ns() {
  GLint64 now = 0;
  glGetInteger64v(GL_TIMESTAMP, &now);
  return now;
}

}  // namespace facet::driver
