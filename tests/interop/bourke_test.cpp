#include "facet/interop/bourke.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "facet/projection/errors.hpp"
#include "facet/projection/warp_inverse.hpp"

namespace facet::interop {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

// A mesh made from a known smooth map: output (a, b) in [0,1]² (y down) shows source position
// (u, v) = (0.5 + 0.4·(a − 0.5) + 0.03·sin(3a), 0.5 − 0.4·(b − 0.5) + 0.02·cos(2b)) (v up).
std::string synthetic_mesh(int nx, int ny, double aspect) {
  std::ostringstream out;
  out.precision(10);
  out << "2\n" << nx << " " << ny << "\n";
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = -aspect + 2 * aspect * i / (nx - 1), y = -1 + 2.0 * j / (ny - 1);
      const double a = double(i) / (nx - 1), b = 1 - double(j) / (ny - 1);
      const double u = 0.5 + 0.4 * (a - 0.5) + 0.03 * std::sin(3 * a);
      const double v = 0.5 - 0.4 * (b - 0.5) + 0.02 * std::cos(2 * b);
      out << x << " " << y << " " << u << " " << v << " " << (i == 0 ? 0.5 : 1.0) << "\n";
    }
  }
  return out.str();
}

TEST(Bourke, RealSphericalMirrorMeshParses) {
  const std::string path =
      std::string(FACET_SHARED_DATA_DIR) + "/warps/sgct-mesh/standard_16x9.data";
  const BourkeMesh mesh = parse_bourke(read_text(path), path);
  EXPECT_EQ(mesh.grid_size, glm::ivec2(100, 60));
  EXPECT_NEAR(mesh.aspect, 16.0 / 9.0, 1e-4);
  // The real mesh, imported at 1920×1080, reproduces its own nodes: each valid node's source
  // position maps back to the node's output position. Worst case over nodes away from unused
  // ones (whose cells hold extrapolated values), in output pixels.
  const ImportedProjector projector = import_bourke(mesh, {}, path, "mirror");
  EXPECT_NO_THROW(projector.warp.validate());
  // By default the fisheye master's centre is overhead (eye +y), its bottom edge the front (−z).
  EXPECT_LE(glm::length(projector.warp.v_eye_from_st({0.5, 0.5}) - glm::dvec3(0, 1, 0)), 1e-12);
  EXPECT_LE(glm::length(projector.warp.v_eye_from_st({0.5, 1.0}) - glm::dvec3(0, 0, -1)), 1e-12);
  // The file's two top corner nodes hold (u, v) = (0, 0) where their neighbours show about
  // (0.46, 0.96) and (0.54, 0.96): each turns its corner cell over. They are masked and reported.
  BourkeMesh unfolded = mesh;
  const std::vector<glm::ivec2> masked = unfold_bourke(unfolded);
  ASSERT_EQ(masked.size(), 2u);
  EXPECT_EQ(masked[0], glm::ivec2(0, 59));
  EXPECT_EQ(masked[1], glm::ivec2(99, 59));
  ASSERT_EQ(projector.notes.size(), 3u);
  EXPECT_NE(projector.notes[0].find("line 5903"), std::string::npos) << projector.notes[0];
  // The mirror's edge crowds the top mesh rows into a sliver of the source image (rows 0.001 apart
  // in v near v = 0.96, against 0.017 between forward rows at the mesh's 100×60): the automatic
  // warp grid is refined until the nodes are followed.
  EXPECT_GT(projector.warp.grid_size.y, 60);
  std::printf("warp grid %d×%d; %s\n", projector.warp.grid_size.x, projector.warp.grid_size.y,
              projector.notes[2].c_str());
  std::vector<double> errors;
  for (int j = 1; j + 1 < 60; ++j) {
    for (int i = 1; i + 1 < 100; ++i) {
      bool interior = true;
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const BourkeNode& n = unfolded.nodes[std::size_t(j + dj) * 100 + i + di];
          interior = interior && n.u >= 0 && n.v >= 0;
        }
      }
      if (!interior) continue;
      const BourkeNode& node = unfolded.nodes[std::size_t(j) * 100 + i];
      const glm::dvec2 q_mesh{(node.x / mesh.aspect + 1) / 2 * 1920, (1 - node.y) / 2 * 1080};
      errors.push_back(glm::length(projector.warp.q_from_st({node.u, 1 - node.v}) - q_mesh));
    }
  }
  ASSERT_GT(errors.size(), 4000u);
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p90 = errors[errors.size() * 9 / 10];
  std::printf("real mirror mesh node error: median %.3f px, p90 %.3f px, max %.3f px\n", median,
              p90, errors.back());
  EXPECT_LT(median, 0.05);
  EXPECT_LT(p90, 0.25);
  EXPECT_LT(errors.back(), 1.0);
  // The mesh shows something at every output pixel but its two masked corners, and so should the
  // warp. Coverage is bilinear between forward nodes; where the mirror crowds many output pixels
  // into one forward cell, ending it at the last node inside the image left the edge pixels of
  // that cell uncovered: 5,110 pixels here, 820 of them more than 5 px inside the border. Nodes
  // just outside the image now count when a cell of theirs reaches into it. What stays uncovered
  // is where the inversion's consistency check dropped the node outside.
  const std::vector<glm::dvec2> st = WarpInverse(projector.warp).st_at_pixel_centres();
  std::size_t uncovered = 0, inside_the_border = 0;
  for (int y = 0; y < 1080; ++y) {
    for (int x = 0; x < 1920; ++x) {
      if (std::isfinite(st[std::size_t(y) * 1920 + x].x)) continue;
      ++uncovered;
      inside_the_border += x >= 5 && x < 1915 && y >= 5 && y < 1075;
    }
  }
  std::printf("uncovered output pixels: %zu, %zu more than 5 px inside the border\n", uncovered,
              inside_the_border);
  EXPECT_EQ(inside_the_border, 0u);
  EXPECT_LE(uncovered, 500u);  // 0.024% of the image
}

TEST(Bourke, SmoothMeshImportsWithinAHundredthOfAPixel) {
  // Nodes every 2 output px, so that bilinear interpolation of the inverse map stays within
  // about 1e-3 px of the analytic map.
  const BourkeMesh mesh = parse_bourke(synthetic_mesh(161, 101, 1.6), "synthetic.data");
  BourkeImportOptions options;
  options.output_size = {320, 200};
  options.warp_grid = {257, 257};
  options.intensity_gamma = 1;
  const ImportedProjector projector = import_bourke(mesh, options, "synthetic.data", "m");
  // Compare the forward warp with the analytic map at output positions between nodes (worst
  // case, output px).
  double worst = 0;
  for (int j = 1; j < 20; ++j) {
    for (int i = 1; i < 20; ++i) {
      const double a = i / 20.0, b = j / 20.0;
      const double u = 0.5 + 0.4 * (a - 0.5) + 0.03 * std::sin(3 * a);
      const double v = 0.5 - 0.4 * (b - 0.5) + 0.02 * std::cos(2 * b);
      const glm::dvec2 q = projector.warp.q_from_st({u, 1 - v});
      worst = std::max(worst, glm::length(q - glm::dvec2(a * 320, b * 200)));
    }
  }
  EXPECT_LT(worst, 0.01);
  // Intensity 0.5 in the first column, 1 elsewhere: the blend follows it.
  ASSERT_TRUE(projector.blend);
  EXPECT_NEAR(projector.blend->at(0, 100), 0.5 + 0.5 * (0.5 / 320 * 160), 1e-3);
  EXPECT_NEAR(projector.blend->at(200, 100), 1.0, 1e-6);
}

TEST(Bourke, BadMeshesNameTheLine) {
  const auto field_of = [](const std::string& text) {
    try {
      parse_bourke(text, "bad.data");
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  const std::string good = synthetic_mesh(3, 2, 1.5);
  EXPECT_EQ(field_of(good), "no error");
  EXPECT_EQ(field_of(""), "line 1");
  EXPECT_EQ(field_of("1\n3 2\n"), "line 1");
  EXPECT_EQ(field_of("2\n3\n"), "line 2");
  EXPECT_EQ(field_of("2\n99999 2\n"), "line 2");
  EXPECT_EQ(field_of("2\n3 2\n-1.5 -1 0 0 1\n"), "nodes");
  std::string bad = good;
  bad.replace(bad.find("\n", bad.find("\n", 2) + 1) + 1, 4, "abc ");
  EXPECT_EQ(field_of(bad), "line 4");
  std::string off_grid = synthetic_mesh(3, 2, 1.5);
  const std::size_t line4 = off_grid.find('\n', off_grid.find('\n', off_grid.find('\n') + 1) + 1);
  off_grid.replace(line4 + 1, 1, "0.3");  // the second node's x: 0 becomes 0.3
  EXPECT_EQ(field_of(off_grid), "line 4");
  EXPECT_EQ(field_of("2\n2 2\n-1 -1 0 0 1\n1 -1 nan 0 1\n-1 1 0 1 1\n1 1 1 1 1\n"), "line 4");
}

TEST(Bourke, AspectMismatchIsAnInputError) {
  const BourkeMesh mesh = parse_bourke(synthetic_mesh(5, 4, 1.6), "m.data");
  BourkeImportOptions options;
  options.output_size = {400, 400};
  EXPECT_THROW(import_bourke(mesh, options, "m.data", "m"), InputError);
}

}  // namespace
}  // namespace facet::interop
