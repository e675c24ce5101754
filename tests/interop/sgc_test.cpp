#include "facet/interop/sgc.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "facet/interop/mpcdi.hpp"
#include "facet/interop/sgct_cluster.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/display_config.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "test_util.hpp"

namespace facet::interop {
namespace {

namespace fs = std::filesystem;
const std::string kDome = std::string(FACET_SHARED_DATA_DIR) + "/warps/sgct-dome/";

std::string read_bytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  EXPECT_TRUE(stream.good()) << path;
  std::ostringstream bytes;
  bytes << stream.rdbuf();
  return bytes.str();
}

// A point inside a random non-degenerate triangle of the mesh, in both spaces.
struct MeshPoint {
  glm::dvec2 st, q_norm;
};
std::vector<MeshPoint> random_mesh_points(const SgcMesh& mesh, int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_int_distribution<std::size_t> pick(0, mesh.triangles.size() - 1);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<MeshPoint> points;
  while (int(points.size()) < count) {
    const glm::uvec3 t = mesh.triangles[pick(random)];
    const SgcVertex &a = mesh.vertices[t.x], &b = mesh.vertices[t.y], &c = mesh.vertices[t.z];
    const glm::dvec2 e1 = b.st - a.st, e2 = c.st - a.st;
    if (std::abs(e1.x * e2.y - e1.y * e2.x) < 1e-12) continue;
    double u = unit(random), v = unit(random);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const MeshPoint p{a.st + u * e1 + v * e2,
                      a.q_norm + u * (b.q_norm - a.q_norm) + v * (c.q_norm - a.q_norm)};
    if (p.st.x < 0 || p.st.y < 0 || p.st.x > 1 || p.st.y > 1) continue;
    points.push_back(p);
  }
  return points;
}

// Worst and RMS distance, output px, between the warp and the mesh's piecewise-linear map.
std::pair<double, double> follow_error_px(const SgcMesh& mesh, const Warp& warp, int count,
                                          unsigned seed) {
  double worst = 0, sum_sq = 0;
  const std::vector<MeshPoint> points = random_mesh_points(mesh, count, seed);
  for (const MeshPoint& p : points) {
    const double e = glm::length(warp.q_from_st(p.st) - p.q_norm * glm::dvec2(warp.output_size));
    worst = std::max(worst, e);
    sum_sq += e * e;
  }
  return {worst, std::sqrt(sum_sq / double(points.size()))};
}

// Asserts that `warp` follows the mesh's piecewise-linear map at 20,000 random points inside its
// triangles (what SGCT draws): worst 0.3 px, RMS 0.05 px, output px; prints both.
void expect_follows_mesh(const SgcMesh& mesh, const Warp& warp, unsigned seed,
                         const std::string& what) {
  const auto [worst, rms] = follow_error_px(mesh, warp, 20000, seed);
  std::printf("%s: warp grid %d×%d, worst %.3f px, RMS %.4f px\n", what.c_str(), warp.grid_size.x,
              warp.grid_size.y, worst, rms);
  EXPECT_LE(worst, 0.3) << what;
  EXPECT_LE(rms, 0.05) << what;
}

// A mesh over a 60°×45° frustum whose map bends smoothly by up to ~3% of the image.
glm::dvec2 bent(glm::dvec2 st) {
  return st + glm::dvec2(0.03 * std::sin(3 * st.y + 1) * st.x, 0.02 * std::cos(2.5 * st.x) * st.y);
}
SgcMesh synthetic_mesh(SgcGridSide side, glm::ivec2 nodes, unsigned seed = 7) {
  SgcMesh mesh;
  mesh.version = 2;
  mesh.q_world_frustum = glm::angleAxis(glm::radians(20.0), glm::dvec3(0, 1, 0));
  mesh.up_deg = 20, mesh.down_deg = -25, mesh.left_deg = -30, mesh.right_deg = 30;
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int j = 0; j < nodes.y; ++j) {
    for (int i = 0; i < nodes.x; ++i) {
      glm::dvec2 g{double(i) / (nodes.x - 1), double(j) / (nodes.y - 1)};
      const bool interior = i > 0 && j > 0 && i + 1 < nodes.x && j + 1 < nodes.y;
      if (side == SgcGridSide::neither && interior) {
        g += glm::dvec2(jitter(random) / (nodes.x - 1), jitter(random) / (nodes.y - 1));
      }
      SgcVertex v;
      if (side == SgcGridSide::texture) {
        v.st = g, v.q_norm = bent(g);
      } else {
        // The inverse: output position g shows the st that bent() sends there (3 fixed-point
        // steps are exact to 1e-6 for this gentle map).
        glm::dvec2 st = g;
        for (int k = 0; k < 8; ++k) st += g - bent(st);
        v.q_norm = g, v.st = st;
      }
      mesh.vertices.push_back(v);
    }
  }
  for (int j = 0; j + 1 < nodes.y; ++j) {
    for (int i = 0; i + 1 < nodes.x; ++i) {
      const std::uint32_t k = std::uint32_t(j * nodes.x + i);
      mesh.triangles.emplace_back(k, k + 1, k + nodes.x);
      mesh.triangles.emplace_back(k + 1, k + nodes.x + 1, k + nodes.x);
    }
  }
  return mesh;
}

TEST(Sgc, RealScissDomeChannelsImportAndFollowTheirMeshes) {
  for (int channel = 1; channel <= 6; ++channel) {
    const std::string path = kDome + "sciss/channel" + std::to_string(channel) + "_planar.sgc";
    SCOPED_TRACE(path);
    const SgcMesh mesh = parse_sgc(read_bytes(path), path);
    EXPECT_EQ(mesh.version, 1);
    EXPECT_EQ(mesh.vertices.size(), 91u * 91u);
    if (channel == 1) {
      // The header as written (degrees, signed edge angles).
      EXPECT_NEAR(mesh.up_deg, 36.0706, 1e-3);
      EXPECT_NEAR(mesh.down_deg, -32.1078, 1e-3);
      EXPECT_NEAR(mesh.left_deg, -47.3247, 1e-3);
      EXPECT_NEAR(mesh.right_deg, 47.5199, 1e-3);
    }
    SgcImportOptions options;
    options.output_size = {1920, 1200};
    const SgcImport imported = import_sgc(mesh, options, path, "channel");
    EXPECT_EQ(imported.side, SgcGridSide::output);
    EXPECT_NO_THROW(imported.projector.warp.validate(path));
    // On its lattice of sevenths the import checks itself against its bound; at random points
    // the helper checks it again.
    EXPECT_LE(imported.worst_follow_px, options.follow_bound_px);
    expect_follows_mesh(mesh, imported.projector.warp, unsigned(channel),
                        "channel " + std::to_string(channel));
  }
}

// Seen from the eye, the six channels of the real dome must tile it: five around from one spring
// line up, one cap, no gap. That holds only if the rotation, the frustum and both flips of the mesh
// are read the way the dome's maker wrote them (a conjugated quaternion, both axes flipped, or the
// roles of position and texture swapped each fail one of the checks below), so it checks the
// conventions against the real installation rather than against our own reading. The masks are
// compared with what they are, not with an ideal: where two have faded in, their sum (γ 2.2) has
// median 1.43, so they do not add up to one; facet keeps them as written, as SGCT does.
TEST(Sgc, RealScissDomeChannelsTileTheDomeSeenFromTheEye) {
  const ImportedDisplay display = import_sgct_cluster(kDome + "sciss/dome_alpha.xml", {});
  ASSERT_EQ(display.projectors.size(), 6u);
  const auto covering = [&](const glm::dvec3& v_eye, std::vector<double>* alphas) {
    int seen_by = 0;
    for (const ImportedProjector& p : display.projectors) {
      const auto st = p.warp.base.st_from_direction(glm::transpose(p.warp.R_eye_base) * v_eye);
      double alpha = -1;
      if (st && st->x >= 0 && st->y >= 0 && st->x <= 1 && st->y <= 1 &&
          p.warp.coverage_at(*st) >= 0.5) {
        const glm::dvec2 q = p.warp.q_from_st(*st);
        if (q.x >= 0 && q.y >= 0 && q.x < p.warp.output_size.x && q.y < p.warp.output_size.y) {
          alpha = p.blend->sample(q);
          ++seen_by;
        }
      }
      if (alphas) alphas->push_back(alpha);
    }
    return seen_by;
  };
  const auto direction = [](double azimuth_deg, double elevation_deg) {
    const double a = glm::radians(azimuth_deg), e = glm::radians(elevation_deg);
    return glm::dvec3(std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a));
  };
  // Each channel's lowest covered elevation, on a 0.25° × 0.05° lattice.
  std::vector<double> lowest(6, 90.0);
  for (double azimuth = -180; azimuth < 180; azimuth += 0.25) {
    for (double elevation = -10; elevation < 30; elevation += 0.05) {
      std::vector<double> alphas;
      covering(direction(azimuth, elevation), &alphas);
      for (int c = 0; c < 6; ++c) {
        if (alphas[c] >= 0) lowest[c] = std::min(lowest[c], elevation);
      }
    }
  }
  std::printf("lowest covered elevation per channel, degrees: %.2f %.2f %.2f %.2f %.2f %.2f\n",
              lowest[0], lowest[1], lowest[2], lowest[3], lowest[4], lowest[5]);
  const double spring_lo = *std::min_element(lowest.begin(), lowest.begin() + 5);
  const double spring_hi = *std::max_element(lowest.begin(), lowest.begin() + 5);
  EXPECT_LE(spring_hi - spring_lo, 2.0);  // the five lower channels start at one spring line
  EXPECT_EQ(lowest[5], 90.0);             // channel 6 is the cap: it lights nothing below 30°
  // 2° above the spring line every direction is lit; where one channel lights alone its mask is
  // bright; where two overlap, both masks have faded in (their sum is what the mask's maker made).
  int samples = 0, holes = 0, overlaps = 0;
  std::vector<double> alone, overlap_sums;
  for (double elevation = spring_hi + 2; elevation < 90; elevation += 0.5) {
    const double step = 0.5 / std::max(0.02, std::cos(glm::radians(elevation)));
    for (double azimuth = -180; azimuth < 180; azimuth += step) {
      std::vector<double> alphas;
      const int seen_by = covering(direction(azimuth, elevation), &alphas);
      ++samples;
      if (seen_by == 0) ++holes;
      double sum = 0;
      int faded_in = 0;
      for (double a : alphas) {
        if (a > 0.01) sum += a, ++faded_in;
      }
      if (seen_by == 1) alone.push_back(sum);
      if (seen_by >= 2) ++overlaps;
      if (faded_in >= 2) overlap_sums.push_back(sum);
    }
  }
  std::sort(alone.begin(), alone.end());
  std::sort(overlap_sums.begin(), overlap_sums.end());
  const auto at = [](const std::vector<double>& v, double p) {
    return v[std::min(v.size() - 1, std::size_t(p * double(v.size())))];
  };
  std::printf(
      "%d directions from 2° above the spring line: %d unlit, %.1f%% in overlaps; lone "
      "channel's alpha p10 %.2f; where two masks are above 0.01 their sum (gamma 2.2) "
      "p10 %.2f, median %.2f, p90 %.2f\n",
      samples, holes, 100.0 * overlaps / samples, at(alone, 0.1), at(overlap_sums, 0.1),
      at(overlap_sums, 0.5), at(overlap_sums, 0.9));
  EXPECT_EQ(holes, 0);
  EXPECT_GT(overlaps, samples / 5);
  EXPECT_LT(overlaps, samples * 3 / 5);
  EXPECT_GE(at(alone, 0.1), 0.75);
}

// The SimCAD exports of another dome hold the same warps as `.sgc` version 1 (`_u2`), version 2
// (`_u3`) and the `_mesh.csv` table; the cluster file next to them gives each projector's
// frustum orientation as heading and pitch.
TEST(Sgc, SimcadMeshesAgreeWithTheirTableAndTheirClusterOrientation) {
  // dome_bravo.xml's <Orientation heading pitch> of projectors 1 to 6, degrees.
  const double heading[6] = {-45, 45, 135, -135, 57, -123}, pitch[6] = {0, 0, 0, 0, 48, 48};
  for (int channel = 1; channel <= 6; ++channel) {
    const std::string stem = kDome + "simcad/channel" + std::to_string(channel) + "_warp";
    SCOPED_TRACE(stem);
    const SgcMesh v1 = parse_sgc(read_bytes(stem + "_u2.sgc"), stem + "_u2.sgc");
    const SgcMesh v2 = parse_sgc(read_bytes(stem + "_u3.sgc"), stem + "_u3.sgc");
    EXPECT_EQ(v1.version, 1);
    EXPECT_EQ(v2.version, 2);
    ASSERT_EQ(v1.vertices.size(), 33u * 33u);
    ASSERT_EQ(v2.vertices.size(), v1.vertices.size());
    ASSERT_EQ(v2.triangles.size(), v1.triangles.size());
    std::istringstream table(read_bytes(stem + "_mesh.csv"));
    std::string line;
    std::getline(table, line);  // x;y;u;v;column;row
    double worst_q = 0, worst_st = 0;
    for (std::size_t k = 0; k < v1.vertices.size(); ++k) {
      ASSERT_TRUE(std::getline(table, line));
      std::replace(line.begin(), line.end(), ';', ' ');
      std::istringstream fields(line);
      double x, y, u, v;
      int column, row;
      ASSERT_TRUE(fields >> x >> y >> u >> v >> column >> row);
      EXPECT_EQ(v1.vertices[k].q_norm, v2.vertices[k].q_norm);
      worst_q = std::max(worst_q, glm::length(v1.vertices[k].q_norm - glm::dvec2(x, y)));
      worst_st = std::max(worst_st, glm::length(v1.vertices[k].st - glm::dvec2(u, v)));
    }
    // The table prints 6 decimals; the .sgc stores floats.
    EXPECT_LE(worst_q, 2e-6);
    EXPECT_LE(worst_st, 2e-6);
    MpcdiFrustum orientation;
    orientation.yaw_deg = heading[channel - 1];
    orientation.pitch_deg = pitch[channel - 1];
    const glm::dmat3 expected = R_eye_frustum(orientation), got = sgc_R_eye_frustum(v1);
    for (int c = 0; c < 3; ++c) EXPECT_LE(glm::length(got[c] - expected[c]), 1e-5) << c;

    SgcImportOptions options;
    options.output_size = {2560, 1600};
    const SgcImport imported = import_sgc(v2, options, stem + "_u3.sgc", "p");
    EXPECT_EQ(imported.side, SgcGridSide::texture);
    expect_follows_mesh(v2, imported.projector.warp, unsigned(channel),
                        "channel " + std::to_string(channel));
  }
}

// The SimCAD XML files hold the same warps as their `.sgc` exports but no frustum: an SGCT cluster
// gives it from viewports with a <PlanarProjection>. dome_bravo.xml, as shipped, names no meshes:
// the `.simcad` files next to it are paired with its viewports by their `_frustum.csv` tables, and
// each channel must come out as its `.sgc` does.
TEST(SgctCluster, SimcadMeshesTakeTheirFrustumFromTheViewport) {
  const ImportedDisplay display = import_sgct_cluster(kDome + "simcad/dome_bravo.xml", {});
  ASSERT_EQ(display.projectors.size(), 6u);
  for (int c = 1; c <= 6; ++c) {
    SCOPED_TRACE(c);
    const Warp& from_simcad = display.projectors[std::size_t(c - 1)].warp;
    EXPECT_EQ(from_simcad.output_size, glm::ivec2(4096, 2160));
    EXPECT_EQ(from_simcad.grid_size, glm::ivec2(33, 33));
    const std::string sgc = kDome + "simcad/channel" + std::to_string(c) + "_warp_u2.sgc";
    const SgcMesh mesh = parse_sgc(read_bytes(sgc), sgc);
    SgcImportOptions options;
    options.output_size = from_simcad.output_size;
    const Warp from_sgc = import_sgc(mesh, options, sgc, "p").projector.warp;
    // The cluster's FOV and Orientation against the mesh's own header (floats).
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(from_simcad.base.tan_extent[std::size_t(k)],
                  from_sgc.base.tan_extent[std::size_t(k)], 1e-5)
          << k;
    }
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(glm::length(from_simcad.R_eye_base[k] - from_sgc.R_eye_base[k]), 1e-5) << k;
    }
    // At the 33×33 nodes (both imports hold them exactly; between nodes the .sgc strip's
    // triangles and the SimCAD grid's bilinear cells part), output px.
    double worst = 0;
    for (int j = 0; j < 33; ++j) {
      for (int i = 0; i < 33; ++i) {
        const glm::dvec2 st{i / 32.0, j / 32.0};
        if (from_sgc.coverage_at(st) < 0.5) continue;
        worst = std::max(worst, glm::length(from_simcad.q_from_st(st) - from_sgc.q_from_st(st)));
      }
    }
    std::printf("channel %d: .simcad against .sgc at the nodes, worst %.5f px\n", c, worst);
    EXPECT_LE(worst, 0.005);  // the .sgc stores floats: 2^-24 of 4096 px is 0.0002 px
  }
  for (int c = 1; c <= 6; ++c) {
    EXPECT_EQ(display.projectors[std::size_t(c - 1)].name, "channel" + std::to_string(c) + "_warp");
  }
  EXPECT_EQ(display.projectors[1].output.window, glm::ivec4(4096, 0, 4096, 2160));
}

// How viewports without a mesh attribute find their `.simcad` files: by the frustum in each
// file's `_frustum.csv` where every file has one, else in order when the counts agree.
TEST(SgctCluster, SimcadMeshesArePairedByTheirFrustumTablesElseInOrder) {
  test::TempFolder scratch("facet-interop-simcad-pairing");
  const std::string shipped = read_bytes(kDome + "simcad/dome_bravo.xml");
  // The first two projectors' viewports swapped: the frustum tables still pair each file with
  // the viewport of its own frustum, so the first projector is channel 2.
  std::string swapped = shipped;
  const std::string first = "heading=\"-45.0\"", second = "heading=\"45.0\"";
  const std::size_t a = swapped.find(first), b = swapped.find(second);
  ASSERT_TRUE(a != std::string::npos && b != std::string::npos && a < b);
  swapped.replace(b, second.size(), first);
  swapped.replace(a, first.size(), second);
  for (int c = 1; c <= 6; ++c) {
    const std::string stem = "channel" + std::to_string(c) + "_warp";
    fs::copy_file(kDome + "simcad/" + stem + ".simcad", scratch.path() / (stem + ".simcad"));
    fs::copy_file(kDome + "simcad/" + stem + "_frustum.csv",
                  scratch.path() / (stem + "_frustum.csv"));
  }
  std::ofstream(scratch.path() / "swapped.xml") << swapped;
  const ImportedDisplay by_frustum = import_sgct_cluster(scratch.path() / "swapped.xml", {});
  ASSERT_EQ(by_frustum.projectors.size(), 6u);
  EXPECT_EQ(by_frustum.projectors[0].name, "channel2_warp");
  EXPECT_EQ(by_frustum.projectors[1].name, "channel1_warp");
  EXPECT_EQ(by_frustum.projectors[2].name, "channel3_warp");
  // Without the tables, in order: the swapped viewports take channels 1 and 2 as they come.
  for (int c = 1; c <= 6; ++c) {
    fs::remove(scratch.path() / ("channel" + std::to_string(c) + "_warp_frustum.csv"));
  }
  const ImportedDisplay in_order = import_sgct_cluster(scratch.path() / "swapped.xml", {});
  ASSERT_EQ(in_order.projectors.size(), 6u);
  EXPECT_EQ(in_order.projectors[0].name, "channel1_warp");
  EXPECT_EQ(in_order.projectors[1].name, "channel2_warp");
  // With the tables, one channel's mesh missing: the others pair, and the viewport left without
  // its projector is an error naming it, not a display with a projector quietly missing.
  {
    test::TempFolder partial("facet-interop-simcad-one-missing");
    for (int c = 1; c <= 6; ++c) {
      if (c == 3) continue;
      const std::string stem = "channel" + std::to_string(c) + "_warp";
      fs::copy_file(kDome + "simcad/" + stem + ".simcad", partial.path() / (stem + ".simcad"));
      fs::copy_file(kDome + "simcad/" + stem + "_frustum.csv",
                    partial.path() / (stem + "_frustum.csv"));
    }
    std::ofstream(partial.path() / "dome_bravo.xml") << shipped;
    try {
      import_sgct_cluster(partial.path() / "dome_bravo.xml", {});
      ADD_FAILURE() << "imported without channel 3";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "Node[3]/Window[0]/Viewport[0]") << e.what();  // Node[0] drives none
      EXPECT_NE(std::string(e.what()).find("_frustum.csv holds this viewport's frustum"),
                std::string::npos)
          << e.what();
    }
  }
  // With one file fewer than viewports nothing is paired, and the error says where meshes come
  // from.
  fs::remove(scratch.path() / "channel6_warp.simcad");
  try {
    import_sgct_cluster(scratch.path() / "swapped.xml", {});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "Node/Window/Viewport@mesh") << e.what();
    EXPECT_NE(std::string(e.what()).find(".simcad files next to the configuration"),
              std::string::npos)
        << e.what();
  }
  // Without a <PlanarProjection> a .simcad mesh cannot be placed.
  std::ofstream(scratch.path() / "bare.xml")
      << "<Cluster><Node><Window><Size x=\"640\" y=\"400\"/><Viewport "
         "mesh=\"channel1_warp.simcad\"/></Window></Node></Cluster>";
  try {
    import_sgct_cluster(scratch.path() / "bare.xml", {});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "Node[0]/Window[0]/Viewport[0]/PlanarProjection") << e.what();
  }
}

TEST(Sgc, SimcadFilesNameTheElement) {
  const SgcMesh frustum = synthetic_mesh(SgcGridSide::texture, {2, 2});
  const auto file = [](const std::string& x, const std::string& y) {
    return "<GeometryFile><GeometryDefinition>" + x + y + "</GeometryDefinition></GeometryFile>";
  };
  const std::string x4 = "<X-FlatParameters range=\"100\">1 2 3 4</X-FlatParameters>";
  const std::string y4 = "<Y-FlatParameters range=\"50\">0 0 1 1</Y-FlatParameters>";
  const SgcMesh good = parse_simcad(file(x4, y4), frustum, "good.simcad");
  ASSERT_EQ(good.vertices.size(), 4u);
  EXPECT_NEAR(good.vertices[3].q_norm.x, 1 + 4 / 100.0, 1e-12);
  EXPECT_NEAR(good.vertices[3].q_norm.y, 1 + 1 / 50.0, 1e-12);
  const struct {
    std::string xml, field;
  } cases[] = {
      {"<GeometryFile>", ""},
      {"<GeometryFile/>", "GeometryFile/GeometryDefinition"},
      {file("", y4), "GeometryFile/GeometryDefinition/X-FlatParameters"},
      {file("<X-FlatParameters>1 2 3 4</X-FlatParameters>", y4),
       "GeometryFile/GeometryDefinition/X-FlatParameters@range"},
      {file("<X-FlatParameters range=\"100\">1 2 x 4</X-FlatParameters>", y4),
       "GeometryFile/GeometryDefinition/X-FlatParameters"},
      {file("<X-FlatParameters range=\"100\">1 2 3</X-FlatParameters>", y4),
       "GeometryFile/GeometryDefinition"},
  };
  for (const auto& c : cases) {
    try {
      parse_simcad(c.xml, frustum, "bad.simcad");
      ADD_FAILURE() << "no error for " << c.xml;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "bad.simcad");
      EXPECT_EQ(e.field(), c.field) << e.what();
    }
  }
}

TEST(Sgc, SyntheticMeshesAreFollowedWhicheverSideIsRegular) {
  for (SgcGridSide side : {SgcGridSide::texture, SgcGridSide::output, SgcGridSide::neither}) {
    SCOPED_TRACE(int(side));
    const SgcMesh mesh = synthetic_mesh(side, {25, 19});
    const SgcMesh read = parse_sgc(format_sgc(mesh, {25, 19}), "synthetic.sgc");
    SgcImportOptions options;
    options.output_size = {800, 600};
    const SgcImport imported = import_sgc(read, options, "synthetic.sgc", "p");
    EXPECT_EQ(imported.side, side);
    expect_follows_mesh(read, imported.projector.warp, 3, "side " + std::to_string(int(side)));
    // The frustum: its centre direction turned 20° left about y.
    const glm::dvec3 axis = imported.projector.warp.R_eye_base * glm::dvec3(0, 0, -1);
    EXPECT_NEAR(axis.x, -std::sin(glm::radians(20.0)), 1e-6);  // stored as floats
  }
}

TEST(Sgc, FormatThenParseGivesTheMeshBack) {
  const SgcMesh mesh = synthetic_mesh(SgcGridSide::neither, {5, 4});
  const SgcMesh read = parse_sgc(format_sgc(mesh, {5, 4}), "m.sgc");
  EXPECT_EQ(read.version, 1);
  ASSERT_EQ(read.vertices.size(), mesh.vertices.size());
  // The strip draws every cell as two triangles that hold its four corners, and nothing else
  // (the diagonal turns with the strip's direction, as in the SCISS files).
  ASSERT_EQ(read.triangles.size(), mesh.triangles.size());
  std::map<int, std::set<std::uint32_t>> corners_of_cell;
  for (glm::uvec3 t : read.triangles) {
    const std::uint32_t row = std::min({t.x / 5, t.y / 5, t.z / 5});
    const std::uint32_t column = std::min({t.x % 5, t.y % 5, t.z % 5});
    for (std::uint32_t v : {t.x, t.y, t.z}) {
      ASSERT_TRUE(v / 5 - row <= 1 && v % 5 - column <= 1) << v;
      corners_of_cell[int(row * 4 + column)].insert(v);
    }
  }
  EXPECT_EQ(corners_of_cell.size(), 12u);
  for (const auto& [cell, corners] : corners_of_cell) EXPECT_EQ(corners.size(), 4u) << cell;
  for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
    EXPECT_LE(glm::length(read.vertices[k].q_norm - mesh.vertices[k].q_norm), 1e-7);
    EXPECT_LE(glm::length(read.vertices[k].st - mesh.vertices[k].st), 1e-7);
  }
  EXPECT_NEAR(read.up_deg, 20, 1e-5);
  EXPECT_NEAR(read.down_deg, -25, 1e-5);
  EXPECT_NEAR(glm::angle(read.q_world_frustum), glm::radians(20.0), 1e-6);
}

TEST(Sgc, BadFilesNameTheField) {
  const std::string good = format_sgc(synthetic_mesh(SgcGridSide::texture, {4, 3}), {4, 3});
  const auto with = [&](std::size_t offset, auto value) {
    std::string bytes = good;
    std::memcpy(bytes.data() + offset, &value, sizeof value);
    return bytes;
  };
  // Offsets: magic 0, version 3, type 4, view floats 8..51, size 52 and 56, vertices from 60.
  const std::size_t indices_at = 60 + 12 * 24;
  const struct {
    std::string bytes, field;
  } cases[] = {
      {"", "magic"},
      {"SGX" + good.substr(3), "magic"},
      {with(3, std::uint8_t(3)), "version"},
      {with(4, std::uint32_t(1)), "mapping type"},
      {with(8, std::numeric_limits<float>::quiet_NaN()), "quaternion x"},
      {with(8, 0.0f).replace(20, 4, std::string(4, '\0')), "quaternion"},
      {with(36, 95.0f), "fov up"},
      {with(40, 30.0f), "fov down"},
      {with(56, std::uint32_t(1u << 30)), "nx ny"},
      {with(60, std::numeric_limits<float>::infinity()), "vertex 0"},
      {good.substr(0, 100), "vertices"},
      {good.substr(0, indices_at + 2), "index count"},
      {good + "x", "index count"},
      {with(indices_at + 4, std::uint32_t(12)), "indices"},
      // Read as version 2: 3 vertices (ny), then vertex data where the index count should be.
      {with(3, std::uint8_t(2)), "index count"},
  };
  for (const auto& c : cases) {
    try {
      parse_sgc(c.bytes, "bad.sgc");
      ADD_FAILURE() << "no error for field " << c.field;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "bad.sgc");
      EXPECT_EQ(e.field(), c.field) << e.what();
    }
  }
}

TEST(Sgc, AFoldedMeshIsRefusedNamingTheTriangle) {
  SgcMesh mesh = synthetic_mesh(SgcGridSide::texture, {6, 5});
  // An interior vertex pushed past its neighbours in the output turns its triangles over.
  mesh.vertices[2 * 6 + 2].q_norm.x += 0.5;
  try {
    import_sgc(mesh, {}, "folded.sgc", "p");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "mesh");
    EXPECT_NE(std::string(e.what()).find("turned over"), std::string::npos) << e.what();
  }
}

TEST(SgctCluster, TheRealDomeConfigurationImportsEveryChannelWithItsMask) {
  const ImportedDisplay display = import_sgct_cluster(kDome + "sciss/dome_alpha.xml", {});
  ASSERT_EQ(display.projectors.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    const ImportedProjector& p = display.projectors[k];
    EXPECT_EQ(p.name, "Channel_" + std::to_string(k + 1));
    EXPECT_EQ(p.warp.output_size, glm::ivec2(1920, 1200));
    EXPECT_EQ(p.output.window, glm::ivec4(1920 * k, 0, 1920, 1200));
    ASSERT_TRUE(p.blend);
    EXPECT_EQ(p.blend->channels, 1);  // the masks are grey stored as RGB
    EXPECT_NO_THROW(p.blend->validate());
    // The configuration names the meshes by another machine's paths: found next to it.
    ASSERT_FALSE(p.notes.empty());
    EXPECT_NE(p.notes[0].find("not found; took \"channel"), std::string::npos) << p.notes[0];
  }
  // The master's GUI viewport has no mesh.
  ASSERT_FALSE(display.notes.empty());
  EXPECT_NE(display.notes[0].find("no correction mesh"), std::string::npos) << display.notes[0];
  // The six render nodes become facet's cluster; the SGCT master drives no projector, so the
  // first node that does is facet's.
  ASSERT_TRUE(display.cluster.has_value());
  ASSERT_EQ(display.cluster->nodes.size(), 6u);
  EXPECT_EQ(display.cluster->master, "node1");
  for (int k = 0; k < 6; ++k) {
    const projection_io::ClusterNode& node = display.cluster->nodes[std::size_t(k)];
    EXPECT_EQ(node.name, "node" + std::to_string(k + 1));
    EXPECT_EQ(node.address,
              "tcp://172.19.1.1" + std::to_string(k + 1) + ":" + std::to_string(7402 + 2 * k));
    EXPECT_EQ(node.projectors, std::vector<std::string>{"Channel_" + std::to_string(k + 1)});
  }
}

TEST(SgctCluster, BadConfigurationsNameTheElement) {
  test::TempFolder scratch("facet-interop-sgct-bad");
  fs::copy_file(kDome + "sciss/channel1_planar.sgc", scratch.path() / "c1.sgc");
  const auto cluster = [](const std::string& window) {
    return "<Cluster><Node><Window>" + window + "</Window></Node></Cluster>";
  };
  const struct {
    std::string xml, field;
  } cases[] = {
      {"<Cluster><Node>", ""},
      {"<Config/>", "Cluster"},
      {cluster("<Size x=\"0\" y=\"10\"/><Viewport mesh=\"c1.sgc\"/>"), "Node[0]/Window[0]/Size"},
      {cluster("<Size x=\"640\" y=\"wide\"/><Viewport mesh=\"c1.sgc\"/>"),
       "Node[0]/Window[0]/Size@y"},
      {cluster("<Size x=\"640\" y=\"400\"/><Viewport mesh=\"c1.data\"/>"),
       "Node[0]/Window[0]/Viewport[0]@mesh"},
      {cluster("<Size x=\"640\" y=\"400\"/><Viewport mesh=\"D:/x/missing.sgc\"/>"),
       "Node[0]/Window[0]/Viewport[0]@mesh"},
      {cluster("<Size x=\"640\" y=\"400\"/><Viewport mesh=\"c1.sgc\" mask=\"none.png\"/>"),
       "Node[0]/Window[0]/Viewport[0]@mask"},
      {cluster("<Size x=\"640\" y=\"400\"/><Viewport mesh=\"c1.sgc\"><Pos x=\"0.5\" "
               "y=\"0\"/><Size x=\"0.6\" y=\"1\"/></Viewport>"),
       "Node[0]/Window[0]/Viewport[0]/Pos"},
      {cluster("<Size x=\"640\" y=\"400\"/><Viewport/>"), "Node/Window/Viewport@mesh"},
  };
  for (const auto& c : cases) {
    const fs::path path = scratch.path() / "cluster.xml";
    std::ofstream(path) << c.xml;
    try {
      import_sgct_cluster(path, {});
      ADD_FAILURE() << "no error for " << c.xml;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), path.string());
      EXPECT_EQ(e.field(), c.field) << e.what();
    }
  }
  // A viewport's part of its window: the output is that part, at its place.
  std::ofstream(scratch.path() / "cluster.xml") << cluster(
      "<Pos x=\"100\" y=\"0\"/><Size x=\"1280\" y=\"400\"/><Viewport mesh=\"c1.sgc\">"
      "<Pos x=\"0.5\" y=\"0\"/><Size x=\"0.5\" y=\"1\"/></Viewport>");
  const ImportedDisplay display = import_sgct_cluster(scratch.path() / "cluster.xml", {});
  ASSERT_EQ(display.projectors.size(), 1u);
  EXPECT_EQ(display.projectors[0].output.window, glm::ivec4(740, 0, 640, 400));
  EXPECT_EQ(display.projectors[0].warp.output_size, glm::ivec2(640, 400));
}

// Export to SGCT, then import: the calibrated sample dome comes back as it went out, seen from
// the eye (the mesh's frustum is not the warp's base, so directions are compared).
TEST(SgctExport, TheCalibratedDomeRoundTripsThroughSgct) {
  const auto config = projection_io::read_display_config(std::string(FACET_SOURCE_DIR) +
                                                         "/configs/displays/dome4/display.json");
  for (double spacing : {8.0, 4.0}) {
    test::TempFolder scratch("facet-interop-sgct-export-" + std::to_string(int(spacing)));
    SgctExportOptions options;
    options.node_spacing_px = spacing;
    for (const auto& [name, bytes] : export_sgct(config, options)) {
      std::ofstream(scratch.path() / name, std::ios::binary) << bytes;
    }
    const ImportedDisplay back = import_sgct_cluster(scratch.path() / "cluster.xml", {});
    ASSERT_EQ(back.projectors.size(), config.projectors.size());
    for (std::size_t p = 0; p < config.projectors.size(); ++p) {
      const Warp original = read_warp(config.resolve(config.projectors[p].warp).string());
      const Warp& imported = back.projectors[p].warp;
      EXPECT_EQ(back.projectors[p].name, config.projectors[p].name);
      EXPECT_EQ(imported.output_size, original.output_size);
      // Where the original shows a direction at least one mesh spacing inside its image, the
      // import shows it at the same output pixel; worst case over a 201×201 st lattice, px.
      const test::DirectionDifference d =
          test::direction_difference(original, imported, spacing, 201);
      std::printf(
          "SGCT round trip, dome4 %s, vertices every %.0f px: %d directions, worst %.4f "
          "px\n",
          config.projectors[p].name.c_str(), spacing, d.compared, d.worst_px);
      EXPECT_EQ(d.uncovered, 0);
      EXPECT_GT(d.compared, 10000);
      // The warp is bilinear in each of its own cells, so it bends along curves of the output
      // that a mesh regular over the output does not follow: the error is first order in the
      // spacing (0.04-0.06 px at 4 px, 0.09-0.15 px at 8 px when this was written).
      EXPECT_LE(d.worst_px, spacing == 4 ? 0.08 : 0.2);
      // The mask carries the blend (8 bits, γ 2.2) where the warp covers the pixel.
      const auto blend = projection_io::read_blend_map(
          config.resolve(*config.projectors[p].blend).string(), original.output_size);
      ASSERT_TRUE(back.projectors[p].blend);
      double worst_alpha = 0;
      const WarpInverse inverse(original);
      for (int y = 0; y < blend.size.y; y += 3) {
        for (int x = 0; x < blend.size.x; x += 3) {
          const double expected = inverse.invert({x + 0.5, y + 0.5}) ? blend.at(x, y) : 0.0;
          worst_alpha =
              std::max(worst_alpha, std::abs(back.projectors[p].blend->at(x, y) - expected));
        }
      }
      EXPECT_LE(worst_alpha, 2.2 / 255 / 2 + 1e-6);  // half an 8-bit step of α^(1/2.2) at α = 1
    }
  }
}

}  // namespace
}  // namespace facet::interop
