// facet patterns: writes the structured-light pattern images of one projector and a manifest.
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/calibration/patterns.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/rig.hpp"
#include "option_flags.hpp"

namespace {

// The shared WxH reader (sscanf's %d wrapped 4294967297 to 1), within the image limits.
glm::ivec2 parse_size(const std::string& text) { return facet::cli::parse_size(text, "--size"); }

struct PatternsArgs {
  std::string size;
  std::string out;
  std::optional<double> phase_period;
  int phase_steps = 4;
  int bit_depth = 8;
};

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const facet::cli::OptionFlags option_flags{"patterns", {{"out", "--out"}}};

const facet::cli::Registration registration{
    20, [](CLI::App& app) {
      auto args = std::make_shared<PatternsArgs>();
      auto* cmd = app.add_subcommand(
          "patterns",
          "Write structured-light patterns (white, black, Gray code with inverses, optional phase "
          "shift) for one projector, plus manifest.json listing each file and its pattern");
      cmd->add_option("--size", args->size, "projector resolution WxH, e.g. 1920x1080")->required();
      cmd->add_option("--out", args->out, "output folder (must not exist, or be empty)")
          ->required();
      cmd->add_option("--phase-period", args->phase_period,
                      "add phase-shift frames with this period in projector pixels");
      cmd->add_option("--phase-steps", args->phase_steps, "number of phase shifts per axis")
          ->check(CLI::Range(3, 64));
      cmd->add_option("--bit-depth", args->bit_depth, "PNG bit depth")
          ->check(CLI::IsMember({8, 16}));
      cmd->callback([args] {
        const glm::ivec2 size = parse_size(args->size);
        facet::calibration::PatternSetOptions options;
        if (args->phase_period) {
          if (!(*args->phase_period >= facet::kMinPhasePeriod &&
                *args->phase_period <= facet::kMaxPhasePeriod)) {
            throw facet::InputError("--phase-period", "",
                                    "a period from 2 to 65536 projector pixels");
          }
          options.phase_period = args->phase_period;
        }
        options.phase_steps = args->phase_steps;
        const auto patterns = facet::calibration::standard_patterns(size, options);
        facet::calibration::write_pattern_folder(args->out, size, patterns, args->bit_depth);
      });
    }};

}  // namespace
