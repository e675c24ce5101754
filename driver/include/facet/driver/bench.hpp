#pragma once
// `facet bench`: every render method over a sweep of settings, side by side in one run, on the
// scenarios of the seed paper (a 360° cylinder, a view deformation through camera textures, a dome
// master and a multi-projector dome), with median frame times, GPU pass times and accuracy
// against the Embree reference.
//
// Timing. Methods are interleaved within every frame (frame k renders every setting once, in an
// order that rotates with k), so that load from other processes hits them alike; wall time is
// measured around render() + glFinish(). Frame k (k = 1..N) looks from the city camera path at
// k · kBenchFrameStepS seconds, so every frame has a new view and the facet pipelines rerun
// passes 1 and 2. On a software rasterizer (llvmpipe) only ratios from one run mean anything.
//
// Accuracy comes from one extra frame at t = 0 (also the warm-up): the ID image of every output
// against the ray-cast reference (compare_ids, wrap_x on 360° outputs), plus a geometric error
// in output pixels whose source depends on the method (BenchRow::geometric_source).
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "facet/driver/render_method.hpp"
#include "facet/driver/scene_view.hpp"
#include "facet/projection/atomic_folder.hpp"

namespace facet::driver {

inline constexpr double kBenchFrameStepS = 0.25;

struct BenchOptions {
  // Any of "cylinder", "deformation", "dome", "scale" and their parts; empty means "all":
  // cylinder, deformation and dome ("scale" only when named).
  std::vector<std::string> scenarios;
  // The scene of every scenario but "scale"'s (which sets its own): a parse_scene_name name.
  std::string scene = "builtin:city";
  // The view of the scenarios that draw `scene` (choose_scene_view; the others take their own
  // scene's default view).
  ViewRequest view;
  // Keep frame 0's view on every timed frame (FrameViews); by default the view moves.
  bool static_view = false;
  int frames = 5;           // timed frames per setting (>= 1)
  double size_scale = 1.0;  // multiplies every output size (and the rig's projector sizes)
  // Small sizes (size_scale · 1/8 unless set otherwise), fewer settings; for tests.
  bool quick = false;
  // The multi-projector dome rig of the dome scenario (facet-rig/1 JSON).
  std::filesystem::path dome_rig = "builtin:dome4";  // load_rig: builtin:NAME or a rig file
};

// One method at one setting on one scenario.
struct BenchSetting {
  std::string method;  // a render_method_names() entry
  std::string label;   // e.g. "pieces=160", "grid=80x60", "tol=0.25px", "face=1024", "tess=4"
  RenderSettings settings;
  // facets-gs: the label of the facets setting whose IDs it must reproduce exactly.
  std::string same_ids_as;
  // Scale fits (bench_scale_fits): the rows of one method with this fit label are fitted together
  // (a facet-count sweep: "pieces=N" for pieces=40, 80, ...); empty: the label.
  std::string fit_label;
};

struct BenchScenario {
  std::string name;         // "cylinder", "deformation-80x60", "dome", "dome4", ...
  std::string description;  // one line
  std::string scene;        // parse_scene_name name; BenchOptions::scene when empty
  // Scale scenarios: the rows fitted together ("scale-cylinder" and "scale-dome" over scene
  // sizes, "scale-facets-cylinder" over facet counts, "scale-width-cylinder" over output widths);
  // the exponent fits (bench_scale_fits) run over the rows of one group, method and fit label.
  std::string scale_group;
  // Depth-image scenarios ("depth"): all of them look from the eye of a DPCI of `scene`
  // (depth_image_pose at the scene's default view), turning on the spot there. With a
  // depth_image_size the scene drawn is that DPCI (render_depth_image at this cylinder size, the
  // cap H x H, meshed at step 1); without, `scene`'s polygons.
  bool depth_image_eye = false;
  glm::ivec2 depth_image_size{0, 0};
  std::vector<OutputSpec> outputs;
  std::vector<BenchSetting> settings;
  // The cube face edge at whose geometric max error run_bench adds a facets tolerance build
  // (with_matched_tolerance); 0: none.
  int matched_cube_face = 0;
};

struct BenchRow {
  std::string scenario, method, setting;
  std::string scene;                   // its --scene name
  std::string scale_group;             // BenchScenario::scale_group
  std::string fit_label;               // BenchSetting::fit_label, else the setting's label
  std::uint64_t triangles_scene = 0;   // Scene::triangle_count()
  std::uint64_t gpu_buffer_bytes = 0;  // RenderStats::gpu_buffer_bytes of the last timed frame
  std::string error;  // non-empty when the setting could not be prepared (then nothing else)
  int outputs = 0;
  std::string output_size;  // "WxH" of the first output
  int frames = 0;
  double frame_ms = 0;  // median wall time of a frame, render + glFinish
  double frame_ms_min = 0, frame_ms_max = 0;
  std::map<std::string, double> pass_ms;  // median GPU ms per pass, summed over outputs
  double gpu_ms = 0;                      // median of the per-frame sum of every pass
  // Facet pipelines only (else nullopt). Passes 1+2's share of the frame:
  // 1 − pass3_only_ms / frame_ms, where pass3_only_ms is the median wall time of a second render
  // of each timed frame's view, which reuses passes 1 and 2 (RenderStats::reused_replication).
  // Wall clock, so it also holds where GPU timer queries cannot attribute time to passes (llvmpipe
  // runs compute work lazily, at the next synchronising call).
  std::optional<double> passes12_share, pass3_only_ms;
  // The same share from the GPU timer: median over frames of (pass1 + pass2) / all passes.
  std::optional<double> passes12_share_gpu;
  std::uint64_t facets = 0, triangles_in = 0, triangles_visible = 0, replicas = 0;
  std::uint64_t dropped_triangles = 0, seam_copies = 0;  // vertex only (RenderStats)
  double replication_ratio = 0;  // mean of replicas / triangles_in over the timed frames
  // Reference comparison on the accuracy frame, pooled over outputs: id_mismatch is
  // Σ mismatched / Σ compared (compare_ids); max_edge_px the largest and p99_edge_px the largest
  // output's p99 of the edge displacement against the exact geometry
  // (ReferenceRaycaster::edge_displacement), which leaves out the differing pixels counted in
  // edge_beyond_window_pixels (more than 4 px). Where many pixels differ the edge figures are
  // over a strided sample: edge_searched_pixels of edge_differing_pixels (EdgeDisplacementOptions).
  double id_mismatch = 0, max_edge_px = 0, p99_edge_px = 0;
  std::uint64_t edge_beyond_window_pixels = 0;
  std::uint64_t edge_differing_pixels = 0, edge_searched_pixels = 0;
  std::uint64_t depth_tie_pixels = 0;  // coinciding surfaces, left out of the edge figures
  // Drawn where the display covers nothing, and the farthest of those from what it covers.
  std::uint64_t outside_display_pixels = 0;
  double outside_display_max_px = 0;
  glm::ivec2 worst_edge_pixel{-1, -1};  // of max_edge_px, in its output
  std::size_t worst_edge_output = 0;
  // Geometric error in output pixels: max (worst case) and RMS; see geometric_source.
  double geometric_max_px = 0, geometric_rms_px = 0;
  // "facet error" (evaluate_facet_error of the facets against the exact warp), "cube texel"
  // (nearest-texel displacement: half a face texel diagonally, mapped into output pixels at
  // every sampled output pixel) or "reference edges" (vertex: its error is the straight chords
  // between projected vertices and depends on the scene, so max/p99 of the reference edge
  // distances stand in for max/RMS).
  std::string geometric_source;
  // facets-gs: pixels whose ID differs from same_ids_as' image on the accuracy frame.
  std::optional<std::uint64_t> id_pixels_differing_from_facets;
  // Scenes with @lod depth images (scene_names.hpp), else nullopt. Before each timed frame the
  // levels are chosen for its eye, and where they change the scene is rebuilt, once for every row
  // of the scenario, outside frame_ms: the rebuilds over the timed frames, the median CPU ms of
  // one (ViewDependentScene::Stats::build_ms), and the median ms of this row's method taking the
  // rebuilt scene (the shared GpuScene's replace_geometry, then RenderMethod::replace_scene, then
  // glFinish).
  std::optional<std::uint64_t> scene_rebuilds;
  std::optional<double> scene_rebuild_ms, scene_replace_ms;
};

// Least-squares slope of log(y) against log(x): the exponent b of y = a · x^b. nullopt when fewer
// than two points have x > 0 and y > 0, or those x are all equal.
std::optional<double> fit_power_exponent(const std::vector<double>& x,
                                         const std::vector<double>& y);

// How the frame time of one method and setting (or fit label) grows over a scale group's rows.
struct BenchScaleFit {
  std::string scale_group, method, setting;  // setting: the rows' fit label
  std::size_t rows = 0;
  // Exponents of median frame ms against the scene's triangles, the facet count and the output
  // width; nullopt where the rows do not vary that quantity (or too few rows ran).
  std::optional<double> triangles_exponent, facets_exponent, width_exponent;
  std::uint64_t triangles_min = 0, triangles_max = 0;
  std::uint64_t facets_min = 0, facets_max = 0;
  int width_min = 0, width_max = 0;
};

// The fits of every scale group in `rows` (rows without a scale group are left out).
std::vector<BenchScaleFit> bench_scale_fits(const std::vector<BenchRow>& rows);

struct BenchReport {
  std::string renderer;  // GL_RENDERER
  int frames = 0;
  double size_scale = 1;
  bool quick = false;
  std::vector<BenchRow> rows;
  std::vector<BenchScaleFit> scale_fits;  // bench_scale_fits(rows)
  std::vector<std::string> notes;  // the closing note: ratios at matched error, shares, ratios
};

// The scenarios of `options`, with their outputs and settings. Throws InputError for an unknown
// scenario name or a bad rig file.
std::vector<BenchScenario> make_bench_scenarios(const BenchOptions& options);

// The scenario's settings, plus `facets` at a tolerance of cube_max_px (the geometric max error
// over the outputs of the cube map at scenario.matched_cube_face) rounded down to 0.001 px, after
// the last facets setting, when the scenario runs that cube map and facet tolerance builds: the
// facets setting at the cube map's own error, which the matched-error ratio asks for.
std::vector<BenchSetting> with_matched_tolerance(const BenchScenario& scenario, double cube_max_px);

// Runs every scenario. Needs a current GL context. `progress` (may be empty) gets one line per
// step.
BenchReport run_bench(const BenchOptions& options, const std::string& renderer,
                      const std::function<void(const std::string&)>& progress = {});

// The closing note of a report's rows (also stored in BenchReport::notes by run_bench).
std::vector<std::string> bench_notes(const std::vector<BenchRow>& rows,
                                     const std::string& renderer);

// True for a folder of an earlier bench: bench.json, and otherwise only bench.csv, bench.md,
// bench.png and bench.log (the log tools/gpu-bench keeps beside them), all regular files.
// write_bench_files may replace such a folder whole.
bool is_bench_output(const std::filesystem::path& folder);

// Writes folder/bench.json, folder/bench.csv, folder/bench.md (a markdown table per scenario,
// then the notes) and folder/bench.png (median frame time against id_mismatch and against
// geometric error, one series per method, one row of panels per scenario) through
// write_folder_atomically, under `rules` (the CLI's take is_bench_output as the command's own
// output): a failure leaves `folder` as it was and no temporary behind.
void write_bench_files(const BenchReport& report, const std::filesystem::path& folder,
                       const OutputFolderRules& rules);

// The CSV columns, in order (bench.csv's header).
std::vector<std::string> bench_csv_columns();

}  // namespace facet::driver
