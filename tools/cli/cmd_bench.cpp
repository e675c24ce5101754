// facet bench: every render method over a sweep of settings, side by side in one run, with median
// frame times and accuracy against the ray-cast reference; writes bench.json, bench.csv and
// bench.png (facet/driver/bench.hpp).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>

#include "command.hpp"
#include "facet/driver/bench.hpp"
#include "facet/driver/cluster.hpp"
#include "facet/driver/gl_context.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"
#include "frames_flag.hpp"
#include "option_flags.hpp"
#include "view_flags.hpp"

namespace facet::cli {
namespace {

using namespace facet::driver;

struct BenchCommandOptions {
  std::string scenario = "all";
  std::int64_t frames = 5;  // signed, so that a negative count is refused, not wrapped
  double size_scale = 1.0;
  std::string out = "out/bench";
  std::string rig = "builtin:dome4";
  std::string scene = "builtin:city";
  ViewFlags view;
  bool quick = false, static_view = false;
};

// --scenario cluster: the cluster protocol alone, no GL (cluster.hpp's bench_cluster).
void run_cluster(const BenchCommandOptions& command) {
  ClusterBenchOptions options;
  if (command.frames != BenchCommandOptions{}.frames)
    options.frames = int(checked_frames(command.frames));
  if (command.quick) {
    options.frames = 50;
    options.node_counts = {2, 3};
  }
  if (command.out.empty()) throw InputError("command line", "--out", "expected a folder");
  // Before the run: --out is new, empty or an earlier cluster bench's (cluster.json alone).
  OutputFolderRules out_rules;
  out_rules.field = "--out";
  out_rules.expected =
      "a new path, an empty folder, or a folder of an earlier cluster bench (cluster.json only)";
  out_rules.is_own_output = [](const std::filesystem::path& folder) {
    return holds_only_files_named(folder,
                                  [](const std::string& name) { return name == "cluster.json"; });
  };
  check_output_folder(command.out, out_rules);
  // The nodes' ipc:// sockets live in a private folder of the system's temporary folder.
  std::string sockets =
      (std::filesystem::temp_directory_path() / "facet-cluster-bench-XXXXXX").string();
  if (!::mkdtemp(sockets.data()))
    throw std::runtime_error("bench: cannot make a folder for the cluster's sockets in " +
                             std::filesystem::temp_directory_path().string());
  struct RemoveAtEnd {
    std::filesystem::path folder;
    ~RemoveAtEnd() {
      std::error_code error;
      std::filesystem::remove_all(folder, error);
    }
  } remove_sockets{sockets};
  options.folder = sockets;
  watch_interrupts();
  const std::vector<ClusterBenchRow> rows = bench_cluster(options, [](const std::string& line) {
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
    throw_if_interrupted("stopped before the end; nothing written");
  });
  nlohmann::json json = nlohmann::json::array();
  for (const ClusterBenchRow& row : rows)
    json.push_back({{"nodes", row.nodes},
                    {"transport", row.transport},
                    {"frame_overhead_median_ms", row.median_ms},
                    {"frame_overhead_p99_ms", row.p99_ms},
                    {"frame_overhead_worst_ms", row.worst_ms},
                    {"deadline_ms", options.deadline_ms},
                    {"frames", options.frames},
                    {"secondary_loss_detected_ms", row.secondary_loss_ms},
                    {"master_loss_detected_ms", row.master_loss_ms},
                    {"bare_nng_median_ms", row.floor_median_ms},
                    {"bare_nng_p99_ms", row.floor_p99_ms},
                    {"bare_nng_expired_frames", row.floor_expired},
                    {"frames_without_every_node", row.frames_short}});
  write_folder_atomically(
      command.out,
      [&](const std::filesystem::path& temporary) {
        std::ofstream file(temporary / "cluster.json");
        file << json.dump(2) << '\n';
        if (!file.flush())
          throw std::runtime_error("bench: writing " + (temporary / "cluster.json").string());
      },
      out_rules);
  std::printf("wrote %s\n", (std::filesystem::path(command.out) / "cluster.json").string().c_str());
}

// The rules of bench's --out: a new path, an empty folder, or the folder of an earlier bench
// (is_bench_output), which is replaced whole; never the current folder, a parent of it, or a
// folder that is or holds the rig or scene file read.
OutputFolderRules bench_out_rules(const BenchCommandOptions& command) {
  OutputFolderRules rules;
  rules.field = "--out";
  rules.expected =
      "a new path, an empty folder, or a folder of an earlier facet bench (bench.json, bench.csv, "
      "bench.md, bench.png, bench.log, nothing else)";
  rules.is_own_output = is_bench_output;
  for (const std::string& input : {command.rig, command.scene}) {
    std::error_code error;
    if (!input.empty() && std::filesystem::exists(input, error)) rules.inputs.emplace_back(input);
  }
  return rules;
}

void run(const BenchCommandOptions& command) {
  if (command.scenario == "cluster") return run_cluster(command);
  BenchOptions options;
  if (command.scenario != "all") options.scenarios = {command.scenario};
  options.frames = int(checked_frames(command.frames));
  options.size_scale = command.size_scale;
  options.quick = command.quick;
  options.dome_rig = command.rig;
  options.scene = command.scene;
  options.static_view = command.static_view;
  options.view = command.view.request();  // malformed flags and scene names before any GL work
  parse_scene_name(command.scene);
  if (command.quick && command.frames == BenchCommandOptions{}.frames) options.frames = 3;
  if (command.out.empty()) throw InputError("command line", "--out", "expected a folder");
  // Before any GL work: an --out that may not be written is refused at once.
  const OutputFolderRules out_rules = bench_out_rules(command);
  check_output_folder(command.out, out_rules);

  auto context = create_headless_context();
  // From here on SIGINT and SIGTERM stop the bench cleanly (Interrupted, exit 128 + signal): at
  // its next progress line, a setting or a timed frame later, or before the files are written.
  watch_interrupts();
  const std::string stopped =
      "stopped before the end (the lines above are what was measured); "
      "nothing written to " +
      command.out;
  const BenchReport report =
      run_bench(options, context->info().renderer, [&stopped](const std::string& line) {
        std::printf("%s\n", line.c_str());
        std::fflush(stdout);
        throw_if_interrupted(stopped);
      });
  throw_if_interrupted(stopped);
  write_bench_files(report, command.out, out_rules);
  std::printf("\n");
  for (const std::string& note : report.notes) std::printf("%s\n\n", note.c_str());
  const std::filesystem::path out(command.out);
  std::printf("wrote %s, %s, %s, %s\n", (out / "bench.json").string().c_str(),
              (out / "bench.csv").string().c_str(), (out / "bench.md").string().c_str(),
              (out / "bench.png").string().c_str());
}

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"bench",
                               {{"scenarios", "--scenario"},
                                {"size_scale", "--size-scale"},
                                {"frames", "--frames"},
                                {"out", "--out"}},
                               ViewFlags::option_flags()};

const Registration registration{
    35, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "bench", "Time against error for every render method, side by side in one run");
      auto options = std::make_shared<BenchCommandOptions>();
      command
          ->add_option("--scenario", options->scenario,
                       "cylinder | deformation[-80x60|-128x128] | dome | dome-master | dome4 | "
                       "scale[-scenes|-facets|-width] | glc[-city|-panorama|-mirror] | depth | "
                       "cluster | all (all: cylinder, "
                       "deformation, dome; scale: its three parts, every method over "
                       "builtin:city, :4, :8 on the cylinder and the dome, the facet methods over "
                       "40 to 320 strips, and every method at three output widths, each with the "
                       "exponent of frame time fitted; glc: the GLC paper cases (cross-slit "
                       "city 1024x320, 360-degree panorama 800x600, mirror sphere 800x800) by "
                       "the glc method; depth: builtin:city and city-fine:8 against DPCIs of "
                       "the city at 512 and 256 on the dome master, from the DPCI's eye; "
                       "cluster: the cluster protocol's cost per frame and loss detection at 2, "
                       "4, 8 nodes, no rendering)")
          ->capture_default_str();
      command
          ->add_option("--frames", options->frames,
                       "Timed frames per setting, 1 to 1000000 (medians; --quick defaults to 3)")
          ->capture_default_str();
      command->add_option("--size-scale", options->size_scale, "Scale every output size by this")
          ->capture_default_str();
      command
          ->add_option("--out", options->out,
                       "Folder for bench.json, bench.csv, bench.md, bench.png")
          ->capture_default_str();
      command
          ->add_option("--rig", options->rig,
                       "The dome4 scenario's rig: builtin:NAME (configs/rigs, compiled in) or a "
                       "rig JSON file")
          ->capture_default_str();
      command
          ->add_option("--scene", options->scene,
                       std::string("Scene of every scenario but scale: ") + kSceneNameSyntax)
          ->capture_default_str();
      options->view.add_to(*command);
      command->add_flag("--static-view", options->static_view,
                        "Keep the accuracy frame's view on every timed frame (default: it moves)");
      command->add_flag("--quick", options->quick,
                        "Small sizes (1/8), 3 frames, fewer settings: for tests");
      command->callback([options] { run(*options); });
    }};

}  // namespace
}  // namespace facet::cli
