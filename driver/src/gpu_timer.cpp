#include "facet/driver/gpu_timer.hpp"

#include "facet/projection/errors.hpp"

namespace facet::driver {

void GpuTimer::begin(std::string_view pass) {
  FACET_ASSERT(!in_pass_);
  Query query;
  if (!free_.empty()) {
    query = std::move(free_.back());
    free_.pop_back();
  } else {
    query = Query::create(GL_TIME_ELAPSED);
  }
  glBeginQuery(GL_TIME_ELAPSED, query.id());
  open_frame_.push_back({std::string(pass), std::move(query)});
  in_pass_ = true;
}

void GpuTimer::end() {
  FACET_ASSERT(in_pass_);
  glEndQuery(GL_TIME_ELAPSED);
  in_pass_ = false;
}

void GpuTimer::end_frame() {
  FACET_ASSERT(!in_pass_);
  frames_.push_back(std::move(open_frame_));
  open_frame_.clear();
}

std::optional<std::vector<PassTime>> GpuTimer::poll(bool wait) {
  if (frames_.empty()) return std::nullopt;
  auto& frame = frames_.front();
  if (!wait)
    for (const auto& pending : frame)
      if (!pending.query.available()) return std::nullopt;
  std::vector<PassTime> times;
  times.reserve(frame.size());
  for (auto& pending : frame) {
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
