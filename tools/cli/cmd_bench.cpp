// facet bench: every render method over a sweep of settings, side by side in one run, with median
// frame times and accuracy against the ray-cast reference; writes bench.json, bench.csv and
// bench.png (facet/driver/bench.hpp).
#include <cstdio>
#include <filesystem>
#include <string>

#include "command.hpp"
#include "facet/driver/bench.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/projection/errors.hpp"

namespace facet::cli {
namespace {

using namespace facet::driver;

struct BenchCommandOptions {
  std::string scenario = "all";
  int frames = 5;
  double size_scale = 1.0;
  std::string out = "out/bench";
  std::string rig = "configs/rigs/dome4.json";
  bool quick = false;
};

void run(const BenchCommandOptions& command) {
  BenchOptions options;
  if (command.scenario != "all") options.scenarios = {command.scenario};
  options.frames = command.frames;
  options.size_scale = command.size_scale;
  options.quick = command.quick;
  options.dome_rig = command.rig;
  if (command.quick && command.frames == BenchCommandOptions{}.frames) options.frames = 3;
  if (command.out.empty()) throw InputError("command line", "--out", "expected a folder");

  auto context = create_headless_context();
  const BenchReport report =
      run_bench(options, context->info().renderer, [](const std::string& line) {
        std::printf("%s\n", line.c_str());
        std::fflush(stdout);
      });
  write_bench_files(report, command.out);
  std::printf("\n");
  for (const std::string& note : report.notes) std::printf("%s\n\n", note.c_str());
  const std::filesystem::path out(command.out);
  std::printf("wrote %s, %s, %s\n", (out / "bench.json").string().c_str(),
              (out / "bench.csv").string().c_str(), (out / "bench.png").string().c_str());
}

const Registration registration{
    35, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "bench", "Time against error for every render method, side by side in one run");
      auto options = std::make_shared<BenchCommandOptions>();
      command
          ->add_option("--scenario", options->scenario,
                       "cylinder | deformation[-80x60|-128x128] | dome | dome-master | dome4 | all")
          ->capture_default_str();
      command
          ->add_option("--frames", options->frames,
                       "Timed frames per setting (medians; --quick defaults to 3)")
          ->capture_default_str();
      command->add_option("--size-scale", options->size_scale, "Scale every output size by this")
          ->capture_default_str();
      command->add_option("--out", options->out, "Folder for bench.json, bench.csv, bench.png")
          ->capture_default_str();
      command->add_option("--rig", options->rig, "The multi-projector dome rig (dome scenario)")
          ->capture_default_str();
      command->add_flag("--quick", options->quick,
                        "Small sizes (1/8), 3 frames, fewer settings: for tests");
      command->callback([options] { run(*options); });
    }};

}  // namespace
}  // namespace facet::cli
