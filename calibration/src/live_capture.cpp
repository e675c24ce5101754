#include "facet/calibration/live_capture.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "facet/calibration/image_io.hpp"
#include "facet/projection/atomic_file.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/progress.hpp"
#include "facet/projection/rig.hpp"

namespace facet::calibration {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The first place where `a` (the journal's) and `b` (this run's) differ, as a JSON-style path;
// empty when they are equal.
std::string first_difference(const json& a, const json& b, const std::string& at) {
  if (a == b) return "";
  if (a.is_object() && b.is_object()) {
    for (const auto& [key, value] : a.items()) {
      const std::string here = at.empty() ? key : at + "." + key;
      if (!b.contains(key)) return here;
      if (std::string d = first_difference(value, b[key], here); !d.empty()) return d;
    }
    for (const auto& [key, value] : b.items()) {
      if (!a.contains(key)) return at.empty() ? key : at + "." + key;
    }
  }
  if (a.is_array() && b.is_array() && a.size() == b.size()) {
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (std::string d = first_difference(a[k], b[k], at + "[" + std::to_string(k) + "]");
          !d.empty()) {
        return d;
      }
    }
  }
  return at;
}

std::string shorten(const json& value) {
  std::string text = value.dump();
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
}

const json* find_path(const json& root, const std::string& path) {
  const json* node = &root;
  std::size_t start = 0;
  while (start < path.size()) {
    if (path[start] == '[') {
      const std::size_t close = path.find(']', start);
      const std::size_t k = std::stoul(path.substr(start + 1, close - start - 1));
      if (!node->is_array() || k >= node->size()) return nullptr;
      node = &(*node)[k];
      start = close + 1;
    } else {
      if (path[start] == '.') ++start;
      const std::size_t end = path.find_first_of(".[", start);
      const std::string key = path.substr(start, end == std::string::npos ? end : end - start);
      if (!node->is_object() || !node->contains(key)) return nullptr;
      node = &(*node)[key];
      start = end == std::string::npos ? path.size() : end;
    }
  }
  return node;
}

// Temporary files of write_atomically (".<stem>.tmp<pid>-<n><ext>") left by a killed run.
void remove_stale_temporaries(const fs::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) return;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.starts_with(".") &&
        name.find(".tmp") != std::string::npos) {
      fs::remove(entry.path(), error);
    }
  }
}

struct Journal {
  json identity;
  std::set<std::string> done;
  bool ends_with_newline = true;
};

Journal read_journal(const fs::path& path) {
  require_regular_file(path);
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(path.string(), "", "a readable capture journal");
  std::stringstream buffer;
  buffer << stream.rdbuf();
  const std::string text = buffer.str();
  Journal journal;
  journal.ends_with_newline = text.empty() || text.back() == '\n';
  std::istringstream lines(text);
  std::string line;
  bool header = true;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    json value;
    try {
      value = json::parse(line);
    } catch (const json::parse_error&) {
      if (header) {
        throw InputError(path.string(), "",
                         std::string("a first line {\"format\": \"") + kCaptureJournalFormat +
                             "\", \"identity\": ...}");
      }
      continue;  // a line torn by a kill during its append
    }
    if (header) {
      if (!value.is_object() || value.value("format", "") != kCaptureJournalFormat ||
          !value.contains("identity")) {
        throw InputError(path.string(), "format",
                         std::string("\"") + kCaptureJournalFormat + "\" with an identity");
      }
      journal.identity = value["identity"];
      header = false;
    } else if (value.is_object() && value.contains("done") && value["done"].is_string()) {
      journal.done.insert(value["done"].get<std::string>());
    }
  }
  if (header) {
    throw InputError(path.string(), "",
                     std::string("a first line {\"format\": \"") + kCaptureJournalFormat +
                         "\", \"identity\": ...}");
  }
  return journal;
}

// A frame is done when its image reads back whole at the camera's size.
bool frame_is_done(const fs::path& path, glm::ivec2 camera_size) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return false;
  try {
    const cv::Mat image = read_luminance(path);
    return image.cols == camera_size.x && image.rows == camera_size.y;
  } catch (const InputError&) {
    return false;
  }
}

}  // namespace

std::vector<CaptureFrame> standard_frames(const std::string& projector_name, glm::ivec2 size,
                                          const PatternSetOptions& options) {
  std::vector<CaptureFrame> frames;
  for (const Pattern& pattern : standard_patterns(size, options)) {
    frames.push_back({fs::path(projector_name) / default_file_name(pattern, ".png"), pattern});
  }
  return frames;
}

void check_live_capture_options(const LiveCaptureOptions& options) {
  if (options.average < 1) throw InputError(OptionName{"average"}, "a number of exposures >= 1");
  if (options.bits != 8 && options.bits != 16) throw InputError(OptionName{"bits"}, "8 or 16");
  if (!(options.camera_gamma > 0 && options.camera_gamma <= kMaxGamma)) {
    throw InputError(OptionName{"camera_gamma"}, "a gamma in (0, 10]");
  }
  if (!(options.max_clipped_fraction >= 0 && options.max_clipped_fraction <= 1)) {
    throw InputError(OptionName{"max_clipped_fraction"}, "a fraction of camera pixels from 0 to 1");
  }
  if (options.out.empty()) throw InputError(OptionName{"out"}, "a capture folder");
  OutputFolderRules rules;
  rules.field = OptionName{"out"};
  rules.expected = std::string(
                       "a new or empty folder, or the folder of an interrupted 'facet capture' (it "
                       "has no ") +
                   kCaptureJournalFile + ")";
  rules.is_own_output = [](const fs::path& folder) {
    std::error_code error;
    return fs::is_regular_file(folder / kCaptureJournalFile, error);
  };
  check_output_folder(options.out, rules);
}

LiveCaptureReport run_live_capture(PatternOutputs& outputs, LiveCamera& camera,
                                   const LiveCaptureSetup& setup,
                                   const LiveCaptureOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto log = [&](const std::string& line) {
    if (options.log) options.log(line);
  };
  check_live_capture_options(options);
  const fs::path out = options.out;
  FACET_ASSERT(setup.model.has_value());
  const glm::ivec2 camera_size = camera.size();
  if (camera_size != setup.model->imager_size()) {
    throw InputError("camera model", "imager_size",
                     "the camera's frame size " + std::to_string(camera_size.x) + "x" +
                         std::to_string(camera_size.y) + ", but the model is for " +
                         std::to_string(setup.model->imager_size().x) + "x" +
                         std::to_string(setup.model->imager_size().y));
  }

  Capture capture;
  capture.folder = out;
  capture.camera = setup.camera;
  capture.camera.model = "camera.cameramodel";
  capture.camera.gamma = 1;
  capture.screen = setup.screen;
  capture.projectors = setup.projectors;
  validate_capture(capture, (out / "capture.json").string());

  const json identity{
      {"capture", capture_to_json(capture)},
      {"camera", camera.identity()},
      {"camera_size", {camera_size.x, camera_size.y}},
      {"lens",
       {{"lensmodel", setup.model->lensmodel()}, {"intrinsics", setup.model->intrinsics()}}},
      {"settings",
       {{"average", options.average},
        {"bits", options.bits},
        {"camera_gamma", options.camera_gamma}}},
      {"setup", setup.identity}};

  const fs::path journal_path = out / kCaptureJournalFile;
  std::error_code error;
  std::set<std::string> journaled;
  bool newline_needed = false;
  if (fs::exists(journal_path, error)) {
    const Journal journal = read_journal(journal_path);
    if (const std::string field = first_difference(journal.identity, identity, "");
        !field.empty()) {
      const json* was = find_path(journal.identity, field);
      const json* now = find_path(identity, field);
      throw InputError(journal_path.string(), "identity." + field,
                       "the same as the interrupted capture in this folder (" +
                           (was ? shorten(*was) : std::string("absent")) + "), but this run has " +
                           (now ? shorten(*now) : std::string("none")) +
                           ": resume with the same display, camera and settings, or capture into a "
                           "new output folder");
    }
    journaled = journal.done;
    newline_needed = !journal.ends_with_newline;
  } else if (fs::exists(out, error) &&
             (!fs::is_directory(out, error) || !fs::is_empty(out, error))) {
    throw InputError(out.string(), OptionName{"out"},
                     std::string("a new or empty folder, or the folder of an interrupted 'facet "
                                 "capture' (it has no ") +
                         kCaptureJournalFile + ")");
  } else {
    fs::create_directories(out);
    const std::string header =
        json{{"format", kCaptureJournalFormat}, {"identity", identity}}.dump() + "\n";
    write_atomically(journal_path, [&](const fs::path& temporary) {
      std::ofstream stream(temporary, std::ios::binary);
      stream << header;
      stream.close();
      if (!stream) throw InputError(journal_path.string(), "", "a writable file");
    });
  }
  remove_stale_temporaries(out);
  for (const CaptureProjector& projector : capture.projectors) {
    for (const CaptureFrame& frame : projector.frames) {
      fs::create_directories(out / frame.file.parent_path());
      remove_stale_temporaries(out / frame.file.parent_path());
    }
  }
  if (!fs::is_regular_file(out / capture.camera.model, error)) {
    setup.model->write(out / capture.camera.model);
  }

  LiveCaptureReport report;
  std::vector<std::vector<bool>> done(capture.projectors.size());
  for (std::size_t p = 0; p < capture.projectors.size(); ++p) {
    for (const CaptureFrame& frame : capture.projectors[p].frames) {
      ++report.frames;
      done[p].push_back(frame_is_done(out / frame.file, camera_size));
      report.kept += done[p].back();
    }
  }
  // capture.json says the capture is whole: not while a frame is missing (deleted since).
  if (report.kept < report.frames) fs::remove(out / "capture.json", error);
  if (report.kept > 0) {
    log("kept " + std::to_string(report.kept) + " of " + std::to_string(report.frames) +
        " frames from an earlier run");
  }

  std::ofstream journal(journal_path, std::ios::binary | std::ios::app);
  if (!journal) throw InputError(journal_path.string(), "", "a writable capture journal");
  if (newline_needed) journal << '\n';
  auto record = [&](const CaptureFrame& frame) {
    journal << json{{"done", frame.file.generic_string()}}.dump() << '\n';
    journal.flush();
    if (!journal) throw InputError(journal_path.string(), "", "a writable capture journal");
  };
  // Frames renamed into place just before a kill, before their journal line.
  for (std::size_t p = 0; p < capture.projectors.size(); ++p) {
    for (std::size_t k = 0; k < done[p].size(); ++k) {
      const CaptureFrame& frame = capture.projectors[p].frames[k];
      if (done[p][k] && !journaled.contains(frame.file.generic_string())) record(frame);
    }
  }

  const std::size_t total_pixels = std::size_t(camera_size.x) * std::size_t(camera_size.y);
  const auto started = std::chrono::steady_clock::now();
  bool stopped = false;
  for (std::size_t p = 0; p < capture.projectors.size() && !stopped; ++p) {
    const CaptureProjector& projector = capture.projectors[p];
    for (std::size_t k = 0; k < projector.frames.size(); ++k) {
      if (done[p][k]) continue;
      if ((options.stop_after && report.captured >= *options.stop_after) ||
          (options.interrupted && options.interrupted())) {
        stopped = true;
        break;
      }
      const CaptureFrame& frame = projector.frames[k];
      outputs.show(p, render_pattern(frame.pattern, projector.size));
      const bool white = frame.pattern.type == PatternType::white;
      cv::Mat sum = cv::Mat::zeros(camera_size.y, camera_size.x, CV_32F);
      cv::Mat brightest;
      for (int r = 0; r < options.average; ++r) {
        cv::Mat grabbed = camera.grab({p, k, std::size_t(r)});
        if (grabbed.type() != CV_32F || grabbed.cols != camera_size.x ||
            grabbed.rows != camera_size.y) {
          throw InputError("camera", "",
                           "frames of " + std::to_string(camera_size.x) + "x" +
                               std::to_string(camera_size.y) + ", but it delivered " +
                               std::to_string(grabbed.cols) + "x" + std::to_string(grabbed.rows));
        }
        if (white) brightest = r == 0 ? grabbed.clone() : cv::max(brightest, grabbed);
        if (options.camera_gamma != 1.0) {
          cv::max(grabbed, 0.0, grabbed);
          cv::pow(grabbed, options.camera_gamma, grabbed);
        }
        sum += grabbed;
      }
      cv::Mat average = options.average == 1 ? sum : sum / double(options.average);
      if (white) {
        cv::Mat clipped = brightest >= 1.0f;
        const double fraction = double(cv::countNonZero(clipped)) / double(total_pixels);
        double white_max = 0;
        cv::minMaxLoc(average, nullptr, &white_max);
        report.exposures.push_back({projector.name, fraction, white_max});
        char line[200];
        std::snprintf(line, sizeof line,
                      "%s: white frame %.3f%% of camera pixels clipped, brightest %.3f of full "
                      "scale",
                      projector.name.c_str(), 100 * fraction, white_max);
        log(line);
        if (fraction > options.max_clipped_fraction && !options.allow_clipping) {
          outputs.blank();
          char expected[400];
          std::snprintf(expected, sizeof expected,
                        "a white frame with at most %.3f%% of camera pixels at full scale, but "
                        "%.3f%% are clipped: lower the camera's exposure time or gain (or the "
                        "projector's brightness) and run again, raise this limit, or allow "
                        "clipping",
                        100 * options.max_clipped_fraction, 100 * fraction);
          throw InputError("projector '" + projector.name + "'", OptionName{"max_clipped_fraction"},
                           expected);
        }
      }
      write_grey_image(out / frame.file, average, options.bits);
      record(frame);
      done[p][k] = true;
      ++report.captured;
      // The frames done of all (an earlier run's included), and the time left at this run's pace:
      // format() takes the time left as elapsed · (all − done) / done, so it is given the time
      // the finished frames would have taken at that pace.
      const double elapsed_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      const std::size_t finished = report.kept + report.captured;
      const double paced_s = finished < report.frames
                                 ? elapsed_s * double(finished) / double(report.captured)
                                 : elapsed_s;
      log(TerminalProgress::format("captured " + frame.file.generic_string(),
                                   {"frames", finished, report.frames}, paced_s, false));
    }
  }
  outputs.blank();
  journal.close();

  const bool all_done = report.kept + report.captured == report.frames;
  if (all_done && report.captured == 0 && fs::is_regular_file(out / "capture.json", error)) {
    report.complete = true;  // finished by an earlier run
  } else if (all_done) {
    if (setup.finish) capture.truth = setup.finish(out);
    if (setup.display) {
      projection_io::write_display_config(*setup.display, out / "display.json");
      capture.display = "display.json";
    }
    write_capture(capture, out / "capture.json");
    report.complete = true;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace facet::calibration
