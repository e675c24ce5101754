#include "facet/calibration/simulate.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <thread>

extern "C" {
#include <mrcal/mrcal.h>
}

#include "facet/calibration/capture.hpp"
#include "facet/calibration/image_io.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::calibration {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Runs body(k) for k in [0, count) on the hardware threads; the first exception propagates.
template <typename Body>
void parallel_tasks(std::size_t count, Body&& body) {
  const std::size_t threads =
      std::max<std::size_t>(1, std::min<std::size_t>(std::thread::hardware_concurrency(), count));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::vector<std::exception_ptr> failures(threads);
  std::vector<std::thread> pool;
  for (std::size_t worker = 0; worker < threads; ++worker) {
    pool.emplace_back([&, worker] {
      try {
        for (std::size_t k = next++; k < count && !failed; k = next++) body(k);
      } catch (...) {
        failures[worker] = std::current_exception();
        failed = true;
      }
    });
  }
  for (auto& thread : pool) thread.join();
  for (auto& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

// Interrupted (after watch_interrupts) once SIGINT or SIGTERM has arrived.
void throw_if_interrupted_after(std::size_t rendered, std::size_t frames,
                                const std::filesystem::path& out) {
  if (const int signal = interrupt_signal())
    throw Interrupted(signal, "stopped after " + std::to_string(rendered) + " of " +
                                  std::to_string(frames) + " frames; nothing written to " +
                                  out.string());
}

}  // namespace

CameraModel rig_camera_model(const RigCamera& camera, const std::string& source) {
  mrcal_lensmodel_t model{};
  if (!mrcal_lensmodel_from_name(&model, camera.lensmodel.c_str()) ||
      !mrcal_lensmodel_type_is_valid(model.type)) {
    throw InputError(
        source, "camera.lensmodel",
        "an mrcal lens model name such as LENSMODEL_STEREOGRAPHIC, not '" + camera.lensmodel + "'");
  }
  if (!camera.intrinsics.empty()) {
    return CameraModel(camera.lensmodel, camera.intrinsics, camera.size, {}, source);
  }
  const int count = mrcal_lensmodel_num_params(&model);
  std::vector<double> intrinsics(std::size_t(std::max(count, 4)), 0.0);
  const double fov = camera.fov_deg * std::numbers::pi / 180.0;
  const double side = std::min(camera.size.x, camera.size.y);
  double f = 0;
  switch (model.type) {
    case MRCAL_LENSMODEL_STEREOGRAPHIC:
    case MRCAL_LENSMODEL_SPLINED_STEREOGRAPHIC:
      if (!(camera.fov_deg > 0 && camera.fov_deg < 360)) {
        throw InputError(source, "camera.fov_deg", "a field of view in (0, 360) degrees");
      }
      f = 0.5 * side / (2 * std::tan(fov / 4));
      break;
    case MRCAL_LENSMODEL_PINHOLE:
    case MRCAL_LENSMODEL_OPENCV4:
    case MRCAL_LENSMODEL_OPENCV5:
    case MRCAL_LENSMODEL_OPENCV8:
    case MRCAL_LENSMODEL_OPENCV12:
      if (!(camera.fov_deg > 0 && camera.fov_deg < 180)) {
        throw InputError(source, "camera.fov_deg",
                         "a field of view in (0, 180) degrees for a pinhole-like lens");
      }
      f = 0.5 * side / std::tan(fov / 2);
      break;
    case MRCAL_LENSMODEL_LONLAT:
    case MRCAL_LENSMODEL_LATLON:
      if (!(camera.fov_deg > 0 && camera.fov_deg <= 360)) {
        throw InputError(source, "camera.fov_deg", "a field of view in (0, 360] degrees");
      }
      f = camera.size.x / fov;
      break;
    default:
      throw InputError(source, "camera.intrinsics",
                       "explicit intrinsics: fov_deg sets up only stereographic, pinhole, OpenCV "
                       "and lon/lat lenses, not " +
                           camera.lensmodel);
  }
  intrinsics[0] = f;
  intrinsics[1] = f;
  intrinsics[2] = 0.5 * (camera.size.x - 1);
  intrinsics[3] = 0.5 * (camera.size.y - 1);
  intrinsics.resize(std::size_t(count));
  return CameraModel(camera.lensmodel, std::move(intrinsics), camera.size, {}, source);
}

ProjectorView view_projector(const Rig& rig, const CameraModel& camera, std::size_t index) {
  FACET_ASSERT(index < rig.projectors.size());
  const ProjectorModel& projector = rig.projectors[index];
  const glm::ivec2 size = camera.imager_size();
  ProjectorView view;
  view.q_projector = cv::Mat(size.y, size.x, CV_64FC2, cv::Scalar(kNaN, kNaN));
  view.irradiance = cv::Mat::zeros(size.y, size.x, CV_32F);
  const glm::dvec3 p_camera = rig.camera.t_eye_camera;
  cv::parallel_for_(cv::Range(0, size.y), [&](const cv::Range& rows) {
    for (int j = rows.start; j < rows.end; ++j) {
      auto* q_row = view.q_projector.ptr<cv::Vec2d>(j);
      auto* e_row = view.irradiance.ptr<float>(j);
      for (int i = 0; i < size.x; ++i) {
        const auto v_camera = camera.unproject(glm::dvec2(i, j));
        if (!v_camera) continue;
        const auto p = screen_hit(rig.screen, p_camera, rig.camera.R_eye_camera * *v_camera);
        if (!p) continue;
        const auto q = projector.q_from_p_eye(*p);
        if (!q) continue;
        // The projector must light the side the camera sees.
        const glm::dvec3 n = screen_normal(rig.screen, *p);
        const glm::dvec3 to_projector = projector.t_eye_projector - *p;
        const double d = glm::length(to_projector);
        const double cos_projector = glm::dot(n, to_projector) / d;
        const double cos_camera = glm::dot(n, p_camera - *p);
        if (!(cos_projector * cos_camera > 0)) continue;
        q_row[i] = cv::Vec2d(q->x, q->y);
        e_row[i] = rig.simulation.falloff ? float(std::abs(cos_projector) / (d * d)) : 1.0f;
      }
    }
  });
  if (rig.simulation.falloff) {
    // Exposure is set for the brightest point of the projector's image the camera sees.
    double brightest = 0;
    for (int j = 0; j < size.y; ++j) {
      for (int i = 0; i < size.x; ++i) {
        const cv::Vec2d q = view.q_projector.at<cv::Vec2d>(j, i);
        if (q[0] >= 0 && q[1] >= 0 && q[0] <= projector.size.x && q[1] <= projector.size.y) {
          brightest = std::max(brightest, double(view.irradiance.at<float>(j, i)));
        }
      }
    }
    if (brightest > 0) view.irradiance *= 1.0 / brightest;
  }
  return view;
}

std::vector<Pattern> simulated_patterns(const Rig& rig, std::size_t index) {
  FACET_ASSERT(index < rig.projectors.size());
  PatternSetOptions options;
  if (rig.simulation.phase) options.phase_period = rig.simulation.phase_period;
  options.phase_steps = rig.simulation.phase_steps;
  return standard_patterns(rig.projectors[index].size, options);
}

std::uint64_t noise_seed(std::uint64_t seed, std::size_t projector, std::size_t frame,
                         std::size_t repeat) {
  std::uint64_t key = splitmix(splitmix(splitmix(seed) ^ projector) ^ frame);
  // Repeat 0 keeps the seed of a single exposure, so one grab per frame equals simulate's frame.
  if (repeat > 0) key = splitmix(key ^ repeat);
  return key;
}

cv::Mat ambient_image(const Rig& rig, glm::ivec2 camera_size) {
  return cv::Mat(camera_size.y, camera_size.x, CV_32F, cv::Scalar(rig.simulation.ambient));
}

void add_projector_light(const Rig& rig, const ProjectorView& view, std::size_t index,
                         const cv::Mat& values, cv::Mat& image) {
  FACET_ASSERT(index < rig.projectors.size());
  const ProjectorModel& projector = rig.projectors[index];
  FACET_ASSERT(values.type() == CV_32F && values.cols == projector.size.x &&
               values.rows == projector.size.y);
  FACET_ASSERT(image.type() == CV_32F && image.size() == view.q_projector.size());
  const SimulationSettings& s = rig.simulation;
  cv::Mat emitted = values.clone();
  if (projector.gamma != 1.0) cv::pow(emitted, projector.gamma, emitted);
  const bool sharp = s.defocus_px <= 0;
  // Defocus spreads light beyond the image edge, so blur a zero-padded copy.
  const int pad = sharp ? 0 : int(std::ceil(4 * s.defocus_px)) + 2;
  cv::Mat light;
  if (sharp) {
    light = emitted;
  } else {
    cv::copyMakeBorder(emitted, light, pad, pad, pad, pad, cv::BORDER_CONSTANT, 0.0);
    cv::GaussianBlur(light, light, cv::Size(0, 0), s.defocus_px, s.defocus_px, cv::BORDER_CONSTANT);
  }
  const int rows = view.q_projector.rows, cols = view.q_projector.cols;
  for (int j = 0; j < rows; ++j) {
    const auto* q_row = view.q_projector.ptr<cv::Vec2d>(j);
    const auto* e_row = view.irradiance.ptr<float>(j);
    auto* out = image.ptr<float>(j);
    for (int i = 0; i < cols; ++i) {
      const cv::Vec2d q = q_row[i];
      if (!(e_row[i] > 0)) continue;
      double value = 0;
      if (sharp) {
        const double c = std::floor(q[0]), r = std::floor(q[1]);
        if (c >= 0 && r >= 0 && c < projector.size.x && r < projector.size.y) {
          value = light.at<float>(int(r), int(c));
        }
      } else {
        // Pixel centres of the padded, blurred image sit at integer + 0.5.
        const double x = q[0] - 0.5 + pad, y = q[1] - 0.5 + pad;
        if (!(x >= 0 && y >= 0 && x <= light.cols - 1 && y <= light.rows - 1)) continue;
        const int x0 = std::min(int(x), light.cols - 2), y0 = std::min(int(y), light.rows - 2);
        const double fx = x - x0, fy = y - y0;
        const float* top = light.ptr<float>(y0);
        const float* bottom = light.ptr<float>(y0 + 1);
        value = (top[x0] * (1 - fx) + top[x0 + 1] * fx) * (1 - fy) +
                (bottom[x0] * (1 - fx) + bottom[x0 + 1] * fx) * fy;
      }
      out[i] += float(s.peak * e_row[i] * value);
    }
  }
}

void finish_camera_image(const Rig& rig, cv::Mat& image, std::size_t projector, std::size_t frame,
                         std::size_t repeat) {
  const SimulationSettings& s = rig.simulation;
  if (s.camera_blur_px > 0) {
    cv::GaussianBlur(image, image, cv::Size(0, 0), s.camera_blur_px, s.camera_blur_px,
                     cv::BORDER_REPLICATE);
  }
  if (s.noise > 0) {
    cv::RNG rng(noise_seed(s.seed, projector, frame, repeat));
    cv::Mat noise(image.rows, image.cols, CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, s.noise);
    image += noise;
  }
}

cv::Mat render_frame(const Rig& rig, const ProjectorView& view, std::size_t index,
                     const Pattern& pattern, std::size_t frame_index, std::size_t repeat) {
  FACET_ASSERT(index < rig.projectors.size());
  cv::Mat image = ambient_image(rig, {view.q_projector.cols, view.q_projector.rows});
  add_projector_light(rig, view, index, render_pattern(pattern, rig.projectors[index].size), image);
  finish_camera_image(rig, image, index, frame_index, repeat);
  return image;
}

SimulationReport simulate_capture(const Rig& rig, const std::filesystem::path& out,
                                  const std::string& source, const ProgressSink& progress) {
  const auto start = std::chrono::steady_clock::now();
  rig.validate(source);
  // Checked before any work (naming the flag), and again when written.
  OutputFolderRules out_rules;
  out_rules.field = OptionName{"out"};
  check_output_folder(out, out_rules);
  const CameraModel camera = rig_camera_model(rig.camera, source);

  Capture capture;
  capture.camera.model = "camera.cameramodel";
  capture.camera.R_eye_camera = rig.camera.R_eye_camera;
  capture.camera.t_eye_camera = rig.camera.t_eye_camera;
  capture.screen = rig.screen;
  capture.truth = "truth";
  struct Task {
    std::size_t projector, frame;
  };
  std::vector<Task> tasks;
  std::vector<std::vector<Pattern>> patterns;
  for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
    const ProjectorModel& projector = rig.projectors[p];
    CaptureProjector entry;
    entry.name = projector.name;
    entry.size = projector.size;
    entry.gamma = projector.gamma;
    patterns.push_back(simulated_patterns(rig, p));
    for (std::size_t k = 0; k < patterns.back().size(); ++k) {
      entry.frames.push_back(
          {std::filesystem::path(projector.name) / default_file_name(patterns.back()[k], ".png"),
           patterns.back()[k]});
      tasks.push_back({p, k});
    }
    capture.projectors.push_back(std::move(entry));
  }
  validate_capture(capture, source);

  SimulationReport report;
  report.camera_size = camera.imager_size();
  report.frames = tasks.size();
  std::vector<ProjectorView> views;
  for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
    views.push_back(view_projector(rig, camera, p));
    const ProjectorModel& projector = rig.projectors[p];
    std::size_t lit = 0;
    const cv::Mat& q = views.back().q_projector;
    for (int j = 0; j < q.rows; ++j) {
      for (int i = 0; i < q.cols; ++i) {
        const cv::Vec2d v = q.at<cv::Vec2d>(j, i);
        lit += v[0] >= 0 && v[1] >= 0 && v[0] < projector.size.x && v[1] < projector.size.y;
      }
    }
    SimulationReport::Truth truth;
    truth.projector = projector.name;
    truth.lit_fraction = double(lit) / double(q.total());
    report.truth.push_back(truth);
  }

  write_folder_atomically(out, [&](const std::filesystem::path& folder) {
    camera.write(folder / capture.camera.model);
    std::filesystem::create_directories(folder / "truth");
    for (const ProjectorModel& projector : rig.projectors) {
      std::filesystem::create_directories(folder / projector.name);
    }
    // Polled before every frame: an Interrupted leaves the pool and write_folder_atomically
    // removes the temporary folder.
    std::atomic<std::size_t> rendered{0};
    std::mutex progress_mutex;
    std::size_t reported = 0;  // under progress_mutex: counts go out in order
    if (progress) progress({"frames", 0, tasks.size()});
    parallel_tasks(tasks.size(), [&](std::size_t k) {
      throw_if_interrupted_after(rendered.load(), tasks.size(), out);
      const Task& task = tasks[k];
      const cv::Mat image = render_frame(rig, views[task.projector], task.projector,
                                         patterns[task.projector][task.frame], task.frame);
      write_grey_image(folder / capture.projectors[task.projector].frames[task.frame].file, image,
                       rig.simulation.bits);
      ++rendered;
      if (progress) {
        const std::lock_guard lock(progress_mutex);
        const std::size_t done = rendered.load();
        if (done > reported) progress({"frames", done, tasks.size()});
        reported = std::max(reported, done);
      }
    });
    throw_if_interrupted_after(rendered.load(), tasks.size(), out);
    for (std::size_t p = 0; p < rig.projectors.size(); ++p) {
      TrueWarpReport warp_report;
      const Warp warp = true_warp(rig, p, {}, &warp_report);
      write_warp((folder / "truth" / (rig.projectors[p].name + ".warp.exr")).string(), warp);
      report.truth[p].base = to_string(warp.base.kind);
      report.truth[p].grid = warp.grid_size;
      report.truth[p].max_checked_error_px = warp_report.max_checked_error_px;
    }
    write_rig(folder / "truth" / "rig.json", rig);
    write_capture(capture, folder / "capture.json");
    throw_if_interrupted_after(rendered.load(), tasks.size(), out);
  });
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace facet::calibration
