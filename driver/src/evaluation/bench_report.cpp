// bench.json, bench.csv, bench.md, bench.png and the closing note of `facet bench`.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "facet/driver/bench.hpp"
#include "facet/projection/atomic_folder.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

std::string format(const char* pattern, auto... values) {
  char text[512];
  std::snprintf(text, sizeof text, pattern, values...);
  return text;
}

std::vector<const BenchRow*> rows_of(const std::vector<BenchRow>& rows, const std::string& scenario,
                                     const std::string& method) {
  std::vector<const BenchRow*> found;
  for (const BenchRow& row : rows) {
    if (row.scenario == scenario && row.method == method && row.error.empty()) {
      found.push_back(&row);
    }
  }
  return found;
}

const BenchRow* row_of(const std::vector<BenchRow>& rows, const std::string& scenario,
                       const std::string& method, const std::string& setting) {
  for (const BenchRow* row : rows_of(rows, scenario, method)) {
    if (row->setting == setting) return row;
  }
  return nullptr;
}

std::vector<std::string> scenarios_of(const std::vector<BenchRow>& rows) {
  std::vector<std::string> names;
  for (const BenchRow& row : rows) {
    if (std::find(names.begin(), names.end(), row.scenario) == names.end()) {
      names.push_back(row.scenario);
    }
  }
  return names;
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

nlohmann::json optional_json(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

nlohmann::json row_json(const BenchRow& row) {
  nlohmann::json j = {{"scenario", row.scenario},
                      {"method", row.method},
                      {"setting", row.setting},
                      {"scene", row.scene},
                      {"triangles_scene", row.triangles_scene},
                      {"outputs", row.outputs},
                      {"output_size", row.output_size}};
  if (!row.scale_group.empty()) {
    j["scale_group"] = row.scale_group;
    j["fit_label"] = row.fit_label;
  }
  if (!row.error.empty()) {
    j["error"] = row.error;
    return j;
  }
  j.update({{"frames", row.frames},
            {"frame_ms", row.frame_ms},
            {"frame_ms_min", row.frame_ms_min},
            {"frame_ms_max", row.frame_ms_max},
            {"gpu_ms", row.gpu_ms},
            {"pass_ms", row.pass_ms},
            {"passes12_share", optional_json(row.passes12_share)},
            {"pass3_only_ms", optional_json(row.pass3_only_ms)},
            {"passes12_share_gpu", optional_json(row.passes12_share_gpu)},
            {"facets", row.facets},
            {"triangles_in", row.triangles_in},
            {"triangles_visible", row.triangles_visible},
            {"replicas", row.replicas},
            {"dropped_triangles", row.dropped_triangles},
            {"seam_copies", row.seam_copies},
            {"gpu_buffer_bytes", row.gpu_buffer_bytes},
            {"gpu_buffer_mib", double(row.gpu_buffer_bytes) / (1024.0 * 1024.0)},
            {"replication_ratio", row.replication_ratio},
            {"id_mismatch", row.id_mismatch},
            {"max_edge_px", row.max_edge_px},
            {"p99_edge_px", row.p99_edge_px},
            {"edge_beyond_window_pixels", row.edge_beyond_window_pixels},
            {"edge_differing_pixels", row.edge_differing_pixels},
            {"edge_searched_pixels", row.edge_searched_pixels},
            {"depth_tie_pixels", row.depth_tie_pixels},
            {"outside_display_pixels", row.outside_display_pixels},
            {"outside_display_max_px", row.outside_display_max_px},
            {"worst_edge_pixel",
             {row.worst_edge_output, row.worst_edge_pixel.x, row.worst_edge_pixel.y}},
            {"geometric_max_px", row.geometric_max_px},
            {"geometric_rms_px", row.geometric_rms_px},
            {"geometric_source", row.geometric_source}});
  if (row.id_pixels_differing_from_facets) {
    j["id_pixels_differing_from_facets"] = *row.id_pixels_differing_from_facets;
  }
  if (row.scene_rebuilds) {
    j["scene_rebuilds"] = *row.scene_rebuilds;
    j["scene_rebuild_ms"] = optional_json(row.scene_rebuild_ms);
    j["scene_replace_ms"] = optional_json(row.scene_replace_ms);
  }
  return j;
}

nlohmann::json scale_fits_json(const std::vector<BenchScaleFit>& fits) {
  nlohmann::json list = nlohmann::json::array();
  for (const BenchScaleFit& fit : fits) {
    list.push_back({{"scale_group", fit.scale_group},
                    {"method", fit.method},
                    {"setting", fit.setting},
                    {"rows", fit.rows},
                    {"triangles_exponent", optional_json(fit.triangles_exponent)},
                    {"facets_exponent", optional_json(fit.facets_exponent)},
                    {"width_exponent", optional_json(fit.width_exponent)},
                    {"triangles", {fit.triangles_min, fit.triangles_max}},
                    {"facets", {fit.facets_min, fit.facets_max}},
                    {"output_width", {fit.width_min, fit.width_max}}});
  }
  return list;
}

std::string csv_text(const BenchReport& report) {
  std::string text;
  const std::vector<std::string> columns = bench_csv_columns();
  for (std::size_t k = 0; k < columns.size(); ++k) text += (k ? "," : "") + columns[k];
  text += "\n";
  for (const BenchRow& row : report.rows) {
    std::string passes;
    for (const auto& [pass, ms] : row.pass_ms) {
      passes += (passes.empty() ? "" : ";") + pass + "=" + format("%.4f", ms);
    }
    const bool ok = row.error.empty();
    auto number = [&](double value) { return ok ? format("%.6g", value) : std::string(); };
    auto count = [&](std::uint64_t value) { return ok ? std::to_string(value) : std::string(); };
    const std::vector<std::string> fields = {
        row.scenario,
        row.method,
        row.setting,
        row.scene,
        std::to_string(row.triangles_scene),
        std::to_string(row.outputs),
        row.output_size,
        ok ? std::to_string(row.frames) : "",
        number(row.frame_ms),
        number(row.frame_ms_min),
        number(row.frame_ms_max),
        number(row.gpu_ms),
        row.passes12_share ? format("%.6g", *row.passes12_share) : "",
        row.pass3_only_ms ? format("%.6g", *row.pass3_only_ms) : "",
        row.passes12_share_gpu ? format("%.6g", *row.passes12_share_gpu) : "",
        passes,
        count(row.facets),
        count(row.triangles_in),
        count(row.triangles_visible),
        count(row.replicas),
        count(row.dropped_triangles),
        count(row.seam_copies),
        count(row.gpu_buffer_bytes),
        number(double(row.gpu_buffer_bytes) / (1024.0 * 1024.0)),
        number(row.replication_ratio),
        number(row.id_mismatch),
        number(row.max_edge_px),
        number(row.p99_edge_px),
        count(row.edge_beyond_window_pixels),
        count(row.depth_tie_pixels),
        count(row.outside_display_pixels),
        number(row.outside_display_max_px),
        number(row.geometric_max_px),
        number(row.geometric_rms_px),
        row.geometric_source,
        row.id_pixels_differing_from_facets ? std::to_string(*row.id_pixels_differing_from_facets)
                                            : "",
        row.scene_rebuilds ? std::to_string(*row.scene_rebuilds) : "",
        row.scene_rebuild_ms ? format("%.6g", *row.scene_rebuild_ms) : "",
        row.scene_replace_ms ? format("%.6g", *row.scene_replace_ms) : "",
        row.error};
    for (std::size_t k = 0; k < fields.size(); ++k) text += (k ? "," : "") + csv_field(fields[k]);
    text += "\n";
  }
  return text;
}

// --- The tables ---------------------------------------------------------------------------------

// One markdown table per scenario, in the rows' order, then the closing notes: what
// driver/README.md's "Measured" section shows.
std::string markdown_text(const BenchReport& report) {
  std::string text =
      "Renderer: " + report.renderer + "; medians of " + std::to_string(report.frames) +
      " frame(s) per row" +
      (report.size_scale != 1 ? format(", outputs at %g of full size", report.size_scale)
                              : std::string()) +
      ".\n";
  std::vector<std::string> scenarios;
  for (const BenchRow& row : report.rows)
    if (std::find(scenarios.begin(), scenarios.end(), row.scenario) == scenarios.end())
      scenarios.push_back(row.scenario);
  for (const std::string& scenario : scenarios) {
    const auto first = std::find_if(report.rows.begin(), report.rows.end(),
                                    [&](const BenchRow& row) { return row.scenario == scenario; });
    text += "\n**" + scenario + "** (" + std::to_string(first->outputs) + " output(s) at " +
            first->output_size + ", " + first->scene + ")\n\n";
    text +=
        "| method | setting | frame ms | passes 1+2 (wall / timer) | facets | repl. ratio | "
        "id_mismatch | edge max / p99 px | geometric max / RMS px |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const BenchRow& row : report.rows) {
      if (row.scenario != scenario) continue;
      if (!row.error.empty()) {
        text += "| " + row.method + " | " + row.setting + " | not run: " + row.error +
                " | | | | | | |\n";
        continue;
      }
      const std::string share =
          row.passes12_share
              ? format("%.0f%% / ", 100 * *row.passes12_share) +
                    (row.passes12_share_gpu ? format("%.0f%%", 100 * *row.passes12_share_gpu)
                                            : std::string("–"))
              : std::string();
      const std::string geometric =
          row.geometric_source == "reference edges"
              ? std::string("(edges)")
              : format("%.3f / %.3f", row.geometric_max_px, row.geometric_rms_px);
      text += "| " + row.method + " | " + row.setting + " | " + format("%.1f", row.frame_ms) +
              " | " + share + " | " + std::to_string(row.facets) + " | " +
              format("%.2f", row.replication_ratio) + " | " + format("%.5f", row.id_mismatch) +
              " | " + format("%.2f / %.2f", row.max_edge_px, row.p99_edge_px) + " | " + geometric +
              " |\n";
    }
  }
  if (!report.notes.empty()) {
    text += "\n";
    for (const std::string& note : report.notes) text += "- " + note + "\n";
  }
  return text;
}

// --- The plot -----------------------------------------------------------------------------------

const cv::Scalar kInk(40, 40, 40), kGrid(225, 225, 225);

cv::Scalar method_colour(const std::string& method) {  // BGR
  if (method == "facets") return {40, 40, 220};
  if (method == "facets-gs") return {0, 150, 250};
  if (method == "tessellated") return {150, 120, 0};
  if (method == "naive") return {200, 90, 30};
  if (method == "cubemap") return {60, 160, 40};
  if (method == "perspective") return {110, 110, 110};
  return {160, 50, 150};
}

// Log-scale axis over [lo, hi], widened to whole decades.
struct LogAxis {
  double lo_exp = 0, hi_exp = 1;
  LogAxis(double lo, double hi) {
    lo_exp = std::floor(std::log10(lo));
    hi_exp = std::ceil(std::log10(hi));
    if (hi_exp <= lo_exp) hi_exp = lo_exp + 1;
  }
  double fraction(double value) const { return (std::log10(value) - lo_exp) / (hi_exp - lo_exp); }
};

void put_text(cv::Mat& image, const std::string& text, cv::Point at, double scale = 0.42,
              const cv::Scalar& colour = kInk) {
  cv::putText(image, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

std::string decade_label(double exponent) {
  if (exponent >= 0 && exponent <= 3) return format("%g", std::pow(10.0, exponent));
  if (exponent < 0 && exponent >= -2) return format("%g", std::pow(10.0, exponent));
  return format("1e%d", int(exponent));
}

// One panel: x = error (log), y = median frame ms (log), one polyline per method through its
// settings in order of error. Values below x_floor are drawn at x_floor (labelled "<=").
void draw_panel(cv::Mat& image, cv::Rect box, const std::vector<const BenchRow*>& rows,
                double (*error_of)(const BenchRow&), double x_floor, const std::string& title,
                const std::string& x_name) {
  double x_lo = 1e300, x_hi = 0, y_lo = 1e300, y_hi = 0;
  for (const BenchRow* row : rows) {
    const double x = std::max(error_of(*row), x_floor);
    x_lo = std::min(x_lo, x);
    x_hi = std::max(x_hi, x);
    y_lo = std::min(y_lo, std::max(row->frame_ms, 1e-3));
    y_hi = std::max(y_hi, std::max(row->frame_ms, 1e-3));
  }
  const cv::Rect plot(box.x + 60, box.y + 30, box.width - 80, box.height - 75);
  cv::rectangle(image, plot, kInk, 1);
  put_text(image, title, {box.x + 60, box.y + 20}, 0.5);
  put_text(image, x_name, {plot.x + plot.width / 2 - 60, plot.y + plot.height + 38});
  put_text(image, "ms", {box.x + 10, plot.y + plot.height / 2});
  if (rows.empty()) return;
  const LogAxis ax(x_lo, x_hi), ay(y_lo, y_hi);
  auto to_pixel = [&](double x, double y) {
    return cv::Point(
        plot.x + int(std::lround(ax.fraction(std::max(x, x_floor)) * plot.width)),
        plot.y + plot.height - int(std::lround(ay.fraction(std::max(y, 1e-3)) * plot.height)));
  };
  for (double e = ax.lo_exp; e <= ax.hi_exp; ++e) {
    const int px = to_pixel(std::pow(10.0, e), std::pow(10.0, ay.lo_exp)).x;
    cv::line(image, {px, plot.y + 1}, {px, plot.y + plot.height - 1}, kGrid, 1);
    std::string label = decade_label(e);
    if (e == ax.lo_exp && std::pow(10.0, e) <= x_floor) label = "<=" + label;
    put_text(image, label, {px - 12, plot.y + plot.height + 18}, 0.38);
  }
  for (double e = ay.lo_exp; e <= ay.hi_exp; ++e) {
    const int py = to_pixel(std::pow(10.0, ax.lo_exp), std::pow(10.0, e)).y;
    cv::line(image, {plot.x + 1, py}, {plot.x + plot.width - 1, py}, kGrid, 1);
    put_text(image, decade_label(e), {box.x + 22, py + 5}, 0.38);
  }
  std::vector<std::string> methods;
  for (const BenchRow* row : rows) {
    if (std::find(methods.begin(), methods.end(), row->method) == methods.end()) {
      methods.push_back(row->method);
    }
  }
  for (std::size_t m = 0; m < methods.size(); ++m) {
    std::vector<const BenchRow*> series;
    for (const BenchRow* row : rows) {
      if (row->method == methods[m]) series.push_back(row);
    }
    std::sort(series.begin(), series.end(),
              [&](const BenchRow* a, const BenchRow* b) { return error_of(*a) < error_of(*b); });
    const cv::Scalar colour = method_colour(methods[m]);
    for (std::size_t k = 0; k < series.size(); ++k) {
      const cv::Point p = to_pixel(error_of(*series[k]), series[k]->frame_ms);
      if (k > 0) {
        cv::line(image, to_pixel(error_of(*series[k - 1]), series[k - 1]->frame_ms), p, colour, 1,
                 cv::LINE_AA);
      }
      cv::circle(image, p, 4, colour, cv::FILLED, cv::LINE_AA);
    }
    const cv::Point legend(plot.x + plot.width - 95, plot.y + 16 + 16 * int(m));
    cv::circle(image, legend, 4, colour, cv::FILLED, cv::LINE_AA);
    put_text(image, methods[m], {legend.x + 10, legend.y + 5}, 0.4, colour);
  }
}

double id_mismatch_of(const BenchRow& row) { return row.id_mismatch; }
double geometric_of(const BenchRow& row) { return row.geometric_max_px; }

cv::Mat plot_image(const BenchReport& report) {
  const std::vector<std::string> scenarios = scenarios_of(report.rows);
  const int panel_w = 560, panel_h = 380, header = 50;
  cv::Mat image(header + panel_h * std::max<int>(1, int(scenarios.size())), 2 * panel_w, CV_8UC3,
                cv::Scalar(255, 255, 255));
  put_text(image,
           format("facet bench: median frame time against error, %d frames, %s", report.frames,
                  report.renderer.c_str()),
           {12, 20}, 0.5);
  put_text(image,
           "Software rasterizer times are meaningful only as ratios within this run. Geometric "
           "error: facet max (facet methods), cube texel (cubemap), image texel (perspective), "
           "reference edge max (vertex).",
           {12, 40}, 0.38);
  for (std::size_t s = 0; s < scenarios.size(); ++s) {
    std::vector<const BenchRow*> rows;
    for (const BenchRow& row : report.rows) {
      if (row.scenario == scenarios[s] && row.error.empty()) rows.push_back(&row);
    }
    const int y = header + int(s) * panel_h;
    draw_panel(image, {0, y, panel_w, panel_h}, rows, &id_mismatch_of, 1e-5,
               scenarios[s] + ": time against ID mismatch", "id_mismatch (fraction of pixels)");
    draw_panel(image, {panel_w, y, panel_w, panel_h}, rows, &geometric_of, 1e-3,
               scenarios[s] + ": time against geometric error", "geometric max error (output px)");
  }
  return image;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw InputError(path.string(), "", "could not be written");
}

}  // namespace

std::vector<std::string> bench_csv_columns() {
  return {"scenario",
          "method",
          "setting",
          "scene",
          "triangles_scene",
          "outputs",
          "output_size",
          "frames",
          "frame_ms",
          "frame_ms_min",
          "frame_ms_max",
          "gpu_ms",
          "passes12_share",
          "pass3_only_ms",
          "passes12_share_gpu",
          "pass_ms",
          "facets",
          "triangles_in",
          "triangles_visible",
          "replicas",
          "dropped_triangles",
          "seam_copies",
          "gpu_buffer_bytes",
          "gpu_buffer_mib",
          "replication_ratio",
          "id_mismatch",
          "max_edge_px",
          "p99_edge_px",
          "edge_beyond_window_pixels",
          "depth_tie_pixels",
          "outside_display_pixels",
          "outside_display_max_px",
          "geometric_max_px",
          "geometric_rms_px",
          "geometric_source",
          "id_pixels_differing_from_facets",
          "scene_rebuilds",
          "scene_rebuild_ms",
          "scene_replace_ms",
          "error"};
}

std::optional<double> fit_power_exponent(const std::vector<double>& x,
                                         const std::vector<double>& y) {
  std::vector<std::pair<double, double>> points;
  for (std::size_t k = 0; k < std::min(x.size(), y.size()); ++k) {
    if (x[k] > 0 && y[k] > 0 && std::isfinite(x[k]) && std::isfinite(y[k])) {
      points.emplace_back(std::log(x[k]), std::log(y[k]));
    }
  }
  if (points.size() < 2) return std::nullopt;
  double mx = 0, my = 0;
  for (const auto& [lx, ly] : points) {
    mx += lx;
    my += ly;
  }
  mx /= double(points.size());
  my /= double(points.size());
  double sxx = 0, sxy = 0;
  for (const auto& [lx, ly] : points) {
    sxx += (lx - mx) * (lx - mx);
    sxy += (lx - mx) * (ly - my);
  }
  // All x equal (to rounding): no slope to fit.
  if (!(sxx > 1e-18 * double(points.size()))) return std::nullopt;
  return sxy / sxx;
}

std::vector<BenchScaleFit> bench_scale_fits(const std::vector<BenchRow>& rows) {
  std::vector<BenchScaleFit> fits;
  std::vector<std::vector<const BenchRow*>> members;
  for (const BenchRow& row : rows) {
    if (row.scale_group.empty() || !row.error.empty()) continue;
    std::size_t k = 0;
    const std::string& label = row.fit_label.empty() ? row.setting : row.fit_label;
    while (k < fits.size() && !(fits[k].scale_group == row.scale_group &&
                                fits[k].method == row.method && fits[k].setting == label)) {
      ++k;
    }
    if (k == fits.size()) {
      fits.push_back({row.scale_group, row.method, label, 0, {}, {}, {}, 0, 0, 0, 0, 0, 0});
      members.emplace_back();
    }
    members[k].push_back(&row);
  }
  for (std::size_t k = 0; k < fits.size(); ++k) {
    BenchScaleFit& fit = fits[k];
    std::vector<double> ms, triangles, facets, width;
    fit.rows = members[k].size();
    fit.triangles_min = fit.facets_min = UINT64_MAX;
    fit.width_min = INT32_MAX;
    for (const BenchRow* row : members[k]) {
      const int w = std::atoi(row->output_size.c_str());  // "WxH"
      ms.push_back(row->frame_ms);
      triangles.push_back(double(row->triangles_scene));
      facets.push_back(double(row->facets));
      width.push_back(double(w));
      fit.triangles_min = std::min(fit.triangles_min, row->triangles_scene);
      fit.triangles_max = std::max(fit.triangles_max, row->triangles_scene);
      fit.facets_min = std::min(fit.facets_min, row->facets);
      fit.facets_max = std::max(fit.facets_max, row->facets);
      fit.width_min = std::min(fit.width_min, w);
      fit.width_max = std::max(fit.width_max, w);
    }
    fit.triangles_exponent = fit_power_exponent(triangles, ms);
    if (fit.facets_max > fit.facets_min) fit.facets_exponent = fit_power_exponent(facets, ms);
    if (fit.width_max > fit.width_min) fit.width_exponent = fit_power_exponent(width, ms);
  }
  return fits;
}

std::vector<std::string> bench_notes(const std::vector<BenchRow>& rows,
                                     const std::string& renderer) {
  std::vector<std::string> notes;
  int frames = 0;
  for (const BenchRow& row : rows) frames = std::max(frames, row.frames);
  notes.push_back(format(
      "Times are medians over %d frames with every method interleaved in each frame, on %s. On a "
      "software rasterizer such as llvmpipe (shared CPU cores) only the ratios within one run "
      "mean anything; absolute times count only on a GPU.",
      frames, renderer.c_str()));
  for (const std::string& scenario : scenarios_of(rows)) {
    // The fastest row on this machine within each error bound, whatever its method.
    std::string fastest;
    for (const double bound_px : {std::numeric_limits<double>::infinity(), 1.0, 0.5, 0.25}) {
      const BenchRow* best = nullptr;
      for (const BenchRow& row : rows) {
        if (row.scenario != scenario || !row.error.empty() || !(row.frame_ms > 0)) continue;
        if (row.geometric_max_px <= bound_px && (!best || row.frame_ms < best->frame_ms))
          best = &row;
      }
      if (!best) continue;
      const std::string bound =
          std::isinf(bound_px) ? std::string("at any error") : format("within %g px", bound_px);
      fastest +=
          format(" %s: %s %s, %.1f ms (max error %.3f px);", bound.c_str(), best->method.c_str(),
                 best->setting.c_str(), best->frame_ms, best->geometric_max_px);
    }
    if (!fastest.empty())
      notes.push_back(scenario + ": fastest on " + renderer +
                      " (frame ms; geometric max error):" + fastest);
    const auto facets = rows_of(rows, scenario, "facets");
    // facets / naive at the same facets (the same error by construction).
    std::string line;
    for (const BenchRow* naive : rows_of(rows, scenario, "naive")) {
      if (const BenchRow* f = row_of(rows, scenario, "facets", naive->setting)) {
        line += format(" %s %.3f (%.1f/%.1f ms);", naive->setting.c_str(),
                       f->frame_ms / naive->frame_ms, f->frame_ms, naive->frame_ms);
      }
    }
    if (!line.empty()) {
      notes.push_back(scenario + ": time facets/naive at the same facets (same error):" + line);
    }
    // facets / cubemap at matched geometric error: the fastest facets setting whose geometric
    // max error is at most the cube map's.
    line.clear();
    for (const BenchRow* cube : rows_of(rows, scenario, "cubemap")) {
      const BenchRow* best = nullptr;
      for (const BenchRow* f : facets) {
        if (f->geometric_max_px <= cube->geometric_max_px &&
            (!best || f->frame_ms < best->frame_ms)) {
          best = f;
        }
      }
      if (best) {
        line += format(
            " %s (%.3f px, id_mismatch %.2g) vs facets %s (%.3f px, id_mismatch %.2g): %.3f;",
            cube->setting.c_str(), cube->geometric_max_px, cube->id_mismatch, best->setting.c_str(),
            best->geometric_max_px, best->id_mismatch, best->frame_ms / cube->frame_ms);
      } else {
        line += format(" %s (%.3f px): no facets setting this accurate was run;",
                       cube->setting.c_str(), cube->geometric_max_px);
      }
    }
    if (!line.empty()) {
      notes.push_back(scenario +
                      ": time facets/cubemap at matched geometric error (fastest facets with "
                      "max error <= the cube map's):" +
                      line);
    }
    line.clear();
    for (const BenchRow* f : facets) {
      if (f->passes12_share) {
        const std::string gpu =
            f->passes12_share_gpu ? format("%.1f%%", 100 * *f->passes12_share_gpu) : "n/a";
        line += format(" %s %.1f%% (%.1f of %.1f ms; GPU timer %s; %llu facets, ratio %.3f);",
                       f->setting.c_str(), 100 * *f->passes12_share,
                       f->frame_ms - f->pass3_only_ms.value_or(0), f->frame_ms, gpu.c_str(),
                       static_cast<unsigned long long>(f->facets), f->replication_ratio);
      }
    }
    if (!line.empty()) {
      notes.push_back(
          scenario +
          ": share of passes 1+2 in the facets frame (wall clock: frame minus a render that "
          "reuses them; paper: under 10%):" +
          line);
    }
    for (const char* method : {"facets-gs", "tessellated"}) {
      for (const BenchRow* gs : rows_of(rows, scenario, method)) {
        if (gs->id_pixels_differing_from_facets) {
          notes.push_back(
              format("%s: %s at %s: %llu ID pixels differ from facets (%s)", scenario.c_str(),
                     method, gs->setting.c_str(),
                     static_cast<unsigned long long>(*gs->id_pixels_differing_from_facets),
                     *gs->id_pixels_differing_from_facets == 0 ? "identical" : "NOT identical"));
        }
      }
    }
  }
  // The paper's replication ratios.
  if (const BenchRow* p160 = row_of(rows, "cylinder", "facets", "pieces=160")) {
    std::string line =
        format("seed setup (cylinder, city) replication ratio: %.3f at 160 pieces (paper: 1.96)",
               p160->replication_ratio);
    if (const BenchRow* tol = row_of(rows, "cylinder", "facets", "tol=0.25px")) {
      line += format(", %.3f at the facet count for 0.25 px (%llu facets)", tol->replication_ratio,
                     static_cast<unsigned long long>(tol->facets));
    }
    notes.push_back(line);
  }
  // Frame cost against scene size, per scale group and method.
  const std::vector<BenchScaleFit> fits = bench_scale_fits(rows);
  std::string group;
  std::string line;
  auto flush = [&] {
    if (!line.empty()) notes.push_back(line);
    line.clear();
  };
  for (const BenchScaleFit& fit : fits) {
    if (fit.scale_group != group) {
      flush();
      group = fit.scale_group;
      line = group +
             ": exponent b of median frame ms ~ x^b, least squares over the group's rows, view "
             "moving, for each x its rows vary:";
    }
    line += format(" %s %s:", fit.method.c_str(), fit.setting.c_str());
    if (fit.triangles_exponent)
      line += format(" triangles %.3f (%llu to %llu)", *fit.triangles_exponent,
                     static_cast<unsigned long long>(fit.triangles_min),
                     static_cast<unsigned long long>(fit.triangles_max));
    if (fit.facets_exponent)
      line += format(" facets %.3f (%llu to %llu)", *fit.facets_exponent,
                     static_cast<unsigned long long>(fit.facets_min),
                     static_cast<unsigned long long>(fit.facets_max));
    if (fit.width_exponent)
      line +=
          format(" width %.3f (%d to %d px)", *fit.width_exponent, fit.width_min, fit.width_max);
    if (!fit.triangles_exponent && !fit.facets_exponent && !fit.width_exponent) line += " n/a";
    line += ";";
  }
  flush();
  for (const char* scenario : {"deformation-80x60", "deformation-128x128"}) {
    line.clear();
    for (const BenchRow* f : rows_of(rows, scenario, "facets")) {
      line += format(" %s %.3f (%llu facets);", f->setting.c_str(), f->replication_ratio,
                     static_cast<unsigned long long>(f->facets));
    }
    if (!line.empty()) {
      notes.push_back(std::string(scenario) +
                      ": view-deformation replication ratio (paper: 10.17 at 80x60):" + line);
    }
  }
  return notes;
}

bool is_bench_output(const std::filesystem::path& folder) {
  std::error_code error;
  return holds_only_files_named(folder,
                                [](const std::string& name) {
                                  return name == "bench.json" || name == "bench.csv" ||
                                         name == "bench.md" || name == "bench.png" ||
                                         name == "bench.log";
                                }) &&
         std::filesystem::is_regular_file(folder / "bench.json", error);
}

void write_bench_files(const BenchReport& report, const std::filesystem::path& folder,
                       const OutputFolderRules& rules) {
  write_folder_atomically(
      folder,
      [&](const std::filesystem::path& temporary) {
        nlohmann::json rows = nlohmann::json::array();
        std::set<std::string> methods;
        for (const BenchRow& row : report.rows) {
          rows.push_back(row_json(row));
          methods.insert(row.method);
        }
        const nlohmann::json json = {{"renderer", report.renderer},
                                     {"frames", report.frames},
                                     {"size_scale", report.size_scale},
                                     {"quick", report.quick},
                                     {"frame_step_s", kBenchFrameStepS},
                                     {"methods", methods},
                                     {"rows", rows},
                                     {"scale_fits", scale_fits_json(report.scale_fits)},
                                     {"notes", report.notes}};
        write_text(temporary / "bench.json", json.dump(2) + "\n");
        write_text(temporary / "bench.csv", csv_text(report));
        write_text(temporary / "bench.md", markdown_text(report));
        if (!cv::imwrite((temporary / "bench.png").string(), plot_image(report))) {
          throw InputError((folder / "bench.png").string(), "", "could not be written");
        }
      },
      rules);
}

}  // namespace facet::driver
