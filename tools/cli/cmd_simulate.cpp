// facet simulate: renders the capture a rig's camera would record, with its ground truth.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/calibration/simulate.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "facet/projection/progress.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "option_flags.hpp"

namespace {

// The shared WxH reader (sscanf's %d wrapped 4294967297 to 1), within the image limits.
glm::ivec2 parse_size(const std::string& text) {
  return facet::cli::parse_size(text, "--camera-size");
}

struct SimulateArgs {
  std::string rig;
  std::string out;
  bool json = false;
  std::optional<double> noise, defocus, camera_blur, ambient, peak, gamma, phase_period;
  std::optional<int> bits;
  std::optional<std::uint64_t> seed;
  std::optional<std::string> camera_size;
  bool no_phase = false, no_falloff = false, clean = false;
};

// The flag that set the rig's `field` (as Rig::validate names it), or "" when none did.
std::string overriding_flag(const SimulateArgs& args, const std::string& field) {
  const struct {
    const char *field, *flag;
    bool given;
  } overrides[] = {{"simulation.noise", "--noise", args.noise.has_value()},
                   {"simulation.defocus_px", "--defocus", args.defocus.has_value()},
                   {"simulation.camera_blur_px", "--camera-blur", args.camera_blur.has_value()},
                   {"simulation.ambient", "--ambient", args.ambient.has_value()},
                   {"simulation.peak", "--peak", args.peak.has_value()},
                   {"simulation.bits", "--bits", args.bits.has_value()},
                   {"camera.size", "--camera-size", args.camera_size.has_value()}};
  for (const auto& o : overrides) {
    if (o.given && field == o.field) return o.flag;
  }
  return "";
}

// Flags override the rig file; each is checked again by Rig::validate, which names the flag.
void apply_overrides(const SimulateArgs& args, facet::Rig& rig) {
  auto& s = rig.simulation;
  if (args.clean) {
    s.noise = 0;
    s.defocus_px = 0;
    s.camera_blur_px = 0;
    s.ambient = 0;
    for (auto& projector : rig.projectors) projector.gamma = 1;
  }
  if (args.noise) s.noise = *args.noise;
  if (args.defocus) s.defocus_px = *args.defocus;
  if (args.camera_blur) s.camera_blur_px = *args.camera_blur;
  if (args.ambient) s.ambient = *args.ambient;
  if (args.peak) s.peak = *args.peak;
  if (args.bits) s.bits = *args.bits;
  if (args.seed) s.seed = *args.seed;
  if (args.phase_period) {
    if (!(*args.phase_period >= facet::kMinPhasePeriod &&
          *args.phase_period <= facet::kMaxPhasePeriod)) {
      throw facet::InputError("--phase-period", "", "a period from 2 to 65536 projector pixels");
    }
    s.phase_period = *args.phase_period;
  }
  if (args.no_phase) s.phase = false;
  if (args.no_falloff) s.falloff = false;
  if (args.gamma) {
    if (!(*args.gamma > 0 && *args.gamma <= facet::kMaxGamma)) {
      throw facet::InputError("--gamma", "", "a gamma in (0, 10]");
    }
    for (auto& projector : rig.projectors) projector.gamma = *args.gamma;
  }
  if (args.camera_size) {
    if (!rig.camera.intrinsics.empty()) {
      throw facet::InputError("--camera-size", "",
                              "a rig camera given by fov_deg: this one has explicit intrinsics");
    }
    rig.camera.size = parse_size(*args.camera_size);
  }
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const facet::cli::OptionFlags option_flags{"simulate", {{"out", "--out"}}};

const facet::cli::Registration registration{
    25, [](CLI::App& app) {
      auto args = std::make_shared<SimulateArgs>();
      auto* cmd = app.add_subcommand(
          "simulate",
          "Render the capture folder a rig's camera would record (capture.json, images, camera "
          "model) with the ground-truth warps in truth/");
      cmd->add_option("--rig", args->rig,
                      "builtin:NAME (configs/rigs: cylinder3, dome4, wall2x2; compiled in) or a "
                      "rig JSON file (configs/rigs/README.md)")
          ->required();
      cmd->add_option("--out", args->out, "capture folder to write (must not exist, or be empty)")
          ->required();
      cmd->add_option("--noise", args->noise, "sensor noise σ, fraction of full scale");
      cmd->add_option("--defocus", args->defocus, "projector defocus σ in projector pixels");
      cmd->add_option("--camera-blur", args->camera_blur, "camera blur σ in camera pixels");
      cmd->add_option("--ambient", args->ambient, "ambient light, fraction of full scale");
      cmd->add_option("--peak", args->peak, "brightest white, fraction of full scale");
      cmd->add_option("--gamma", args->gamma, "gamma of every projector");
      cmd->add_option("--bits", args->bits, "PNG bits per sample, 8 or 16");
      cmd->add_option("--seed", args->seed, "noise seed")->check(facet::cli::unsigned_only());
      cmd->add_option("--phase-period", args->phase_period, "phase period in projector pixels");
      cmd->add_flag("--no-phase", args->no_phase, "Gray code only, no phase-shift frames");
      cmd->add_flag("--no-falloff", args->no_falloff, "uniform brightness (no 1/d², no cosine)");
      cmd->add_flag("--clean", args->clean,
                    "no noise, blur, ambient light, and gamma 1 (later flags still apply)");
      cmd->add_option("--camera-size", args->camera_size, "camera imager WxH, e.g. 1280x1024");
      cmd->add_flag("--json", args->json, "Print a JSON report");
      cmd->callback([args] {
        facet::Rig rig = facet::load_rig(args->rig);
        apply_overrides(*args, rig);
        try {
          rig.validate(args->rig + " (with the command-line overrides)");
        } catch (const facet::InputError& error) {
          const std::string flag = overriding_flag(*args, error.field());
          if (flag.empty()) throw;
          throw facet::InputError(flag, "", error.expected());
        }
        // From here on SIGINT and SIGTERM stop the simulation cleanly (exit 128 + signal).
        facet::watch_interrupts();
        facet::TerminalProgress progress(stderr, "facet simulate");
        const auto report =
            facet::calibration::simulate_capture(rig, args->out, args->rig, progress.sink());
        progress.finish();
        if (args->json) {
          nlohmann::json truth = nlohmann::json::array();
          for (const auto& t : report.truth) {
            truth.push_back({{"projector", t.projector},
                             {"base", t.base},
                             {"grid", {t.grid.x, t.grid.y}},
                             {"max_checked_error_px", t.max_checked_error_px},
                             {"lit_fraction", t.lit_fraction}});
          }
          const nlohmann::json out{{"out", args->out},
                                   {"camera_size", {report.camera_size.x, report.camera_size.y}},
                                   {"frames", report.frames},
                                   {"truth", truth},
                                   {"seconds", report.seconds}};
          std::cout << out.dump(2) << "\n";
          return;
        }
        std::printf("%s: %zu frames of %dx%d in %.1f s\n", args->out.c_str(), report.frames,
                    report.camera_size.x, report.camera_size.y, report.seconds);
        for (const auto& t : report.truth) {
          std::printf("  %-12s sees %5.1f%% of the camera image; truth %s %dx%d nodes, %.4f px\n",
                      t.projector.c_str(), 100 * t.lit_fraction, t.base.c_str(), t.grid.x, t.grid.y,
                      t.max_checked_error_px);
        }
      });
    }};

}  // namespace
