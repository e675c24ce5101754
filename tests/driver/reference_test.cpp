// The accuracy oracle: the Embree ray cast on hand-made scenes whose ID images are known
// pixel-exactly, and compare_ids on crafted images with known mismatches and edge shifts.
#include "facet/driver/reference.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <random>

#include "facet/driver/render_method.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {
namespace {

// Appends an axis-aligned rectangle in the plane z = z0 (object frame) as one object of two
// triangles, (0,1,2) and (0,2,3), counter-clockwise seen from +z (the eye at the origin looking
// down −z sees the front when front_to_eye, else the back).
void add_rectangle(Scene& scene, glm::vec2 lo, glm::vec2 hi, float z0, bool front_to_eye = true,
                   const glm::mat4& T_world_object = glm::mat4(1)) {
  const auto first_vertex = std::uint32_t(scene.positions.size());
  const glm::vec3 corners[4] = {
      {lo.x, lo.y, z0}, {hi.x, lo.y, z0}, {hi.x, hi.y, z0}, {lo.x, hi.y, z0}};
  for (const auto& p : corners) {
    scene.positions.push_back(p);
    scene.normals.push_back({0, 0, 1});
    scene.uvs.push_back({0, 0});
  }
  Primitive primitive;
  primitive.first_index = std::uint32_t(scene.indices.size());
  primitive.index_count = 6;
  const std::uint32_t front[6] = {0, 1, 2, 0, 2, 3}, back[6] = {0, 2, 1, 0, 3, 2};
  for (std::uint32_t k : front_to_eye ? front : back) scene.indices.push_back(first_vertex + k);
  Object object;
  object.name = "rectangle " + std::to_string(scene.objects.size());
  object.T_world_object = T_world_object;
  object.first_primitive = std::uint32_t(scene.primitives.size());
  object.primitive_count = 1;
  scene.primitives.push_back(primitive);
  scene.objects.push_back(object);
  if (scene.materials.empty()) scene.materials.push_back(Material{});
  scene.update_bounds();
}

// A perspective output of 200×200 with tangents ±1: pixel centre (x + 0.5, y + 0.5) looks along
// (tan_x, tan_y, −1) with tan_x = (x + 0.5)/100 − 1 and tan_y = 1 − (y + 0.5)/100.
Warp square_view() { return Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), {200, 200}); }

// The expected ID image of a rectangle spanning tan_x in (-0.5, 0.5), tan_y in (-0.25, 0.25):
// x in [50, 149], y in [75, 124]. Its diagonal from the (-0.5, -0.25) corner to (0.5, 0.25) is
// tan_y = tan_x / 2, i.e. x + 2y = 298.5, which no pixel centre meets: the first triangle
// (lower right) holds x + 2y > 298.5.
std::uint32_t expected_rectangle_id(int x, int y, std::uint32_t first_id) {
  if (x < 50 || x > 149 || y < 75 || y > 124) return 0;
  return x + 2 * y > 298 ? first_id : first_id + 1;
}

TEST(ReferenceIds, RectangleStraightAheadIsPixelExact) {
  Scene scene;
  add_rectangle(scene, {-1, -0.5f}, {1, 0.5f}, -2);
  const auto ids = reference_ids(scene, square_view(), glm::dmat4(1));
  ASSERT_EQ(ids.size(), 200u * 200u);
  int wrong = 0;
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      if (ids[std::size_t(y) * 200 + x] != expected_rectangle_id(x, y, 1)) ++wrong;
    }
  }
  EXPECT_EQ(wrong, 0);
}

TEST(ReferenceIds, NumberingOcclusionTransformsAndBackFaces) {
  Scene scene;
  // Object 0: far behind, large, seen from the back: hidden by culling.
  add_rectangle(scene, {-100, -100}, {100, 100}, -50, /*front_to_eye=*/false);
  // Object 1: a wall behind the rectangle covering the whole view, front facing; in the eye
  // frame it spans x in [-80, 80], y in [-40, 40], so its diagonal is tan_y = tan_x / 2 too.
  add_rectangle(scene, {-80, -37}, {80, 43}, -20);
  // Object 2: the rectangle of expected_rectangle_id, built 5 m to the left of the origin and
  // moved back by its object transform; the eye sits 3 m up the y axis and is moved back by
  // T_eye_world.
  add_rectangle(scene, {-6, 2.5f}, {-4, 3.5f}, -2, true,
                glm::translate(glm::mat4(1), glm::vec3(5, 0, 0)));
  const glm::dmat4 T_eye_world = glm::translate(glm::dmat4(1), glm::dvec3(0, -3, 0));
  const auto base = scene_triangle_base(scene);
  ASSERT_EQ(base[2], 4u);

  ReferenceRaycaster culled(scene);
  EXPECT_EQ(culled.triangle_count(), 6u);
  const auto ids = culled.ids(WarpInverse(square_view()), T_eye_world);
  int wrong = 0;
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      std::uint32_t expected = expected_rectangle_id(x, y, base[2] + 1);
      if (expected == 0) {
        expected = base[1] + 1 + (x + 2 * y > 298 ? 0 : 1);
      }
      if (ids[std::size_t(y) * 200 + x] != expected) ++wrong;
    }
  }
  EXPECT_EQ(wrong, 0);

  // Without culling, the back-facing object 0 is still behind the wall; turn the wall around and
  // object 0 shows through where the rectangle does not cover.
  Scene turned;
  add_rectangle(turned, {-100, -100}, {100, 100}, -50, false);
  add_rectangle(turned, {-40, -40}, {40, 40}, -20, false);
  const ReferenceRaycaster both_sides(turned, {.cull_back_faces = false});
  const ReferenceRaycaster front_only(turned, {.cull_back_faces = true});
  const glm::dvec3 eye(0), ahead(0.1, 0.05, -1);
  EXPECT_NE(both_sides.id_along(eye, ahead), 0u);
  EXPECT_LE(both_sides.id_along(eye, ahead), 4u);
  EXPECT_GE(both_sides.id_along(eye, ahead), 3u);  // the nearer, turned wall
  EXPECT_EQ(front_only.id_along(eye, ahead), 0u);  // every triangle faces away
  // Looking backwards (+z) sees nothing at all.
  EXPECT_EQ(both_sides.id_along(eye, {0, 0, 1}), 0u);
  // The near distance skips the wall 20 m ahead but not the back plane 50 m ahead.
  const ReferenceRaycaster far_only(turned, {.cull_back_faces = false, .near_m = 30});
  const std::uint32_t far_id = far_only.id_along(eye, ahead);
  EXPECT_TRUE(far_id == 1u || far_id == 2u) << far_id;
}

TEST(ReferenceIds, UncoveredPixelsAreZero) {
  Scene scene;
  add_rectangle(scene, {-40, -40}, {40, 40}, -20);
  Warp warp = square_view();
  warp.grid_size = {3, 3};
  warp.offset_px.assign(9, glm::vec2(0));
  warp.coverage.assign(9, 1.0f);
  // The left column of nodes uncovered: coverage crosses 0.5 at s = 0.25, x = 50 px.
  for (int j = 0; j < 3; ++j) warp.coverage[warp.node_index(0, j)] = 0;
  const auto ids = reference_ids(scene, warp, glm::dmat4(1));
  for (int y = 0; y < 200; y += 9) {
    for (int x = 0; x < 200; ++x) {
      EXPECT_EQ(ids[std::size_t(y) * 200 + x] == 0, x < 50) << x << ", " << y;
    }
  }
}

// Reference: ID 1 left of x = 50, ID 2 from x = 50 on, 100×40.
std::vector<std::uint32_t> two_halves() {
  std::vector<std::uint32_t> image(100 * 40);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 100; ++x) image[std::size_t(y) * 100 + x] = x < 50 ? 1 : 2;
  }
  return image;
}

TEST(CompareIds, IdenticalImagesHaveNoError) {
  const auto reference = two_halves();
  const IdComparison c = compare_ids(reference, reference, {100, 40});
  EXPECT_EQ(c.id_mismatch, 0.0);
  EXPECT_EQ(c.max_edge_px, 0.0);
  EXPECT_EQ(c.differing_pixels, 0u);
  // Columns 49 and 50 touch the edge.
  EXPECT_EQ(c.compared_pixels, 100u * 40u - 2u * 40u);
}

TEST(CompareIds, ShiftedEdgeFarBlobAndAbsentId) {
  const auto reference = two_halves();
  auto tested = reference;
  // The edge drawn 3 px too far right: columns 50, 51, 52 show ID 1, at 1, 2 and 3 px from the
  // nearest reference pixel of ID 1 (column 49).
  for (int y = 0; y < 40; ++y) {
    for (int x = 50; x < 53; ++x) tested[std::size_t(y) * 100 + x] = 1;
  }
  IdComparison c = compare_ids(reference, tested, {100, 40});
  EXPECT_EQ(c.differing_pixels, 3u * 40u);
  EXPECT_EQ(c.mismatched_pixels, 2u * 40u);  // column 50 is next to the edge: not compared
  EXPECT_DOUBLE_EQ(c.id_mismatch, 80.0 / 3920.0);
  EXPECT_DOUBLE_EQ(c.max_edge_px, 3.0);
  EXPECT_EQ(c.absent_id_pixels, 0u);

  // One pixel of ID 1 at (90, 20): 41 px from column 49, beyond the local ring search.
  tested[20 * 100 + 90] = 1;
  // One pixel of an ID the reference never shows.
  tested[5 * 100 + 80] = 77;
  c = compare_ids(reference, tested, {100, 40});
  EXPECT_DOUBLE_EQ(c.max_edge_px, 41.0);
  EXPECT_EQ(c.absent_id_pixels, 1u);
  EXPECT_EQ(c.differing_pixels, 3u * 40u + 2u);
  EXPECT_EQ(c.mismatched_pixels, 2u * 40u + 2u);
  // 120 distances of 1, 2, 3 and one of 41: the 99th percentile is the rank-119 value, 3.
  EXPECT_DOUBLE_EQ(c.p99_edge_px, 3.0);

  // A diagonal neighbour: 2 px right and 2 px down of a reference ID-1 pixel.
  auto diagonal = reference;
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 100; ++x) diagonal[std::size_t(y) * 100 + x] = 2;
  }
  diagonal[10 * 100 + 10] = 1;
  auto tested_diagonal = diagonal;
  tested_diagonal[12 * 100 + 12] = 1;
  // The reference shows ID 1 at one pixel only: too sparse for an edge distance by default,
  // measured when every triangle counts.
  c = compare_ids(diagonal, tested_diagonal, {100, 40});
  EXPECT_EQ(c.max_edge_px, 0.0);
  EXPECT_EQ(c.sparse_id_pixels, 1u);
  c = compare_ids(diagonal, tested_diagonal, {100, 40}, {.min_reference_pixels = 1});
  EXPECT_DOUBLE_EQ(c.max_edge_px, std::sqrt(8.0));
  EXPECT_EQ(c.sparse_id_pixels, 0u);
}

// A sliver: the reference hits ID 3 at two pixel centres 30 px apart along a row (a thin
// triangle lying between the centres elsewhere); the tested image hits it at the centre between
// them, 15 px from both. Its distance measures sampling, not an edge shift: left out below
// min_reference_pixels, and counted.
TEST(CompareIds, SparseTrianglesAreCountedNotMeasured) {
  auto reference = two_halves();
  reference[10 * 100 + 60] = 3;
  reference[10 * 100 + 90] = 3;
  auto tested = reference;
  tested[10 * 100 + 75] = 3;
  IdComparison c = compare_ids(reference, tested, {100, 40});
  EXPECT_EQ(c.differing_pixels, 1u);
  EXPECT_EQ(c.sparse_id_pixels, 1u);
  EXPECT_EQ(c.absent_id_pixels, 0u);
  EXPECT_EQ(c.max_edge_px, 0.0);
  // Still a mismatch away from edges: the comparison does not hide it.
  EXPECT_EQ(c.mismatched_pixels, 1u);
  c = compare_ids(reference, tested, {100, 40}, {.min_reference_pixels = 2});
  EXPECT_DOUBLE_EQ(c.max_edge_px, 15.0);
  EXPECT_EQ(c.sparse_id_pixels, 0u);
}

// A 360° panorama: column 0 and column 99 are neighbours with wrap_x.
TEST(CompareIds, WrapXJoinsTheLeftAndRightColumns) {
  // ID 1 only in column 99, ID 2 elsewhere; the tested image shows ID 1 in column 1 as well:
  // 2 px round the seam, 98 px across the image.
  std::vector<std::uint32_t> edge_ref(100 * 40, 2);
  for (int y = 0; y < 40; ++y) edge_ref[std::size_t(y) * 100 + 99] = 1;
  auto edge_tested = edge_ref;
  for (int y = 0; y < 40; ++y) edge_tested[std::size_t(y) * 100 + 1] = 1;
  const IdComparison across = compare_ids(edge_ref, edge_tested, {100, 40});
  const IdComparison round = compare_ids(edge_ref, edge_tested, {100, 40}, {.wrap_x = true});
  EXPECT_DOUBLE_EQ(across.max_edge_px, 98.0);
  EXPECT_DOUBLE_EQ(round.max_edge_px, 2.0);
  // Column 0 touches column 99's ID 1 only round the seam: one column more near an edge.
  EXPECT_EQ(across.compared_pixels, 100u * 40u - 2u * 40u);
  EXPECT_EQ(round.compared_pixels, 100u * 40u - 3u * 40u);
  // Column 1 was compared without wrap_x and is a mismatch there; with wrap_x it still is (its
  // neighbours 0 and 2 are both ID 2).
  EXPECT_EQ(across.mismatched_pixels, 40u);
  EXPECT_EQ(round.mismatched_pixels, 40u);
}

// Random blobs of IDs, and a tested image with pixels moved near and far from their ID (some
// more than 8 px, across rows and the wrapped seam): the edge figures equal a brute-force
// nearest pixel of the same ID, with and without wrap_x.
TEST(CompareIds, FarPixelsMatchABruteForceSearch) {
  const glm::ivec2 size(90, 50);
  std::mt19937 random(7);
  std::vector<std::uint32_t> reference(std::size_t(size.x) * size.y, 0);
  for (std::uint32_t id = 1; id <= 12; ++id) {
    const int x0 = int(random() % 80), y0 = int(random() % 40), w = 3 + int(random() % 10),
              h = 3 + int(random() % 10);
    for (int y = y0; y < std::min(size.y, y0 + h); ++y)
      for (int x = x0; x < std::min(size.x, x0 + w); ++x)
        reference[std::size_t(y) * size.x + x] = id;
  }
  std::vector<std::uint32_t> tested = reference;
  for (int k = 0; k < 300; ++k) tested[random() % tested.size()] = std::uint32_t(random() % 13);
  for (const bool wrap_x : {false, true}) {
    SCOPED_TRACE(wrap_x ? "wrap_x" : "no wrap");
    const IdComparison c = compare_ids(reference, tested, size, {.wrap_x = wrap_x});
    std::map<std::uint32_t, std::size_t> counts;
    for (std::uint32_t id : reference) ++counts[id];
    std::vector<double> edge_px;
    for (int y = 0; y < size.y; ++y) {
      for (int x = 0; x < size.x; ++x) {
        const std::uint32_t id = tested[std::size_t(y) * size.x + x];
        if (id == reference[std::size_t(y) * size.x + x] || counts[id] < 16) continue;
        long best = std::numeric_limits<long>::max();
        for (int v = 0; v < size.y; ++v) {
          for (int u = 0; u < size.x; ++u) {
            if (reference[std::size_t(v) * size.x + u] != id) continue;
            long dx = std::abs(u - x);
            if (wrap_x) dx = std::min(dx, long(size.x) - dx);
            best = std::min(best, dx * dx + long(v - y) * (v - y));
          }
        }
        edge_px.push_back(std::sqrt(double(best)));
      }
    }
    ASSERT_GT(edge_px.size(), 100u);
    ASSERT_GT(*std::max_element(edge_px.begin(), edge_px.end()), 8.0) << "no far pixel tried";
    EXPECT_DOUBLE_EQ(c.max_edge_px, *std::max_element(edge_px.begin(), edge_px.end()));
    const std::size_t k = std::min(edge_px.size() - 1, std::size_t(0.99 * double(edge_px.size())));
    std::nth_element(edge_px.begin(), edge_px.begin() + std::ptrdiff_t(k), edge_px.end());
    EXPECT_DOUBLE_EQ(c.p99_edge_px, edge_px[k]);
  }
}

TEST(CompareIds, WrongSizesAreInputErrors) {
  const auto reference = two_halves();
  EXPECT_THROW(compare_ids(reference, std::vector<std::uint32_t>(10), {100, 40}), InputError);
  EXPECT_THROW(compare_ids(reference, reference, {100, 41}), InputError);
}

// The rectangle of expected_rectangle_id drawn 2 px too far right: columns 50 and 51 lose it
// (tested ID 0; the exact edge tan_x = -0.5 is q.x = 50, 0.5 and 1.5 px from their centres),
// columns 150 and 151 gain it (the edge q.x = 150, again 0.5 and 1.5 px), and the diagonal
// moves 2 px along x, 2/√5 ≈ 0.89 px across. The worst is 1.5 px, at the columns that show
// nothing, computed from the rectangle's edge.
TEST(EdgeDisplacement, ShiftedRectangleIsMeasuredAgainstTheExactEdges) {
  Scene scene;
  add_rectangle(scene, {-1, -0.5f}, {1, 0.5f}, -2);
  const ReferenceRaycaster raycaster(scene);
  const Warp warp = square_view();
  const WarpInverse inverse(warp);
  const std::vector<std::uint32_t> reference = raycaster.ids(inverse, glm::dmat4(1));
  EdgeDisplacement e =
      raycaster.edge_displacement(inverse, glm::dmat4(1), reference, reference, {});
  EXPECT_EQ(e.differing_pixels, 0u);
  EXPECT_EQ(e.max_px, 0.0);

  std::vector<std::uint32_t> tested(reference.size());
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      tested[std::size_t(y) * 200 + x] = x < 2 ? 0 : expected_rectangle_id(x - 2, y, 1);
    }
  }
  e = raycaster.edge_displacement(inverse, glm::dmat4(1), reference, tested, {});
  EXPECT_GT(e.differing_pixels, 4u * 50u);
  EXPECT_EQ(e.beyond_window, 0u);
  EXPECT_EQ(e.measured_pixels, e.differing_pixels);
  EXPECT_GE(e.max_px, 1.5 - 1e-9);
  EXPECT_LE(e.max_px, 1.5 + 1e-6);
  EXPECT_LE(e.p99_px, e.max_px);

  // A pixel showing the rectangle's upper-left triangle 29.5 px left of its edge q.x = 50:
  // beyond the 4 px window, counted and left out of max_px.
  tested[100 * 200 + 20] = 2;
  e = raycaster.edge_displacement(inverse, glm::dmat4(1), reference, tested, {});
  EXPECT_EQ(e.beyond_window, 1u);
  EXPECT_GE(e.max_px, 1.5 - 1e-9);
  EXPECT_LE(e.max_px, 1.5 + 1e-6);
  // A wider window reaches it; a triangle's distance is computed, not searched.
  e = raycaster.edge_displacement(inverse, glm::dmat4(1), reference, tested, {.window_px = 32});
  EXPECT_EQ(e.beyond_window, 0u);
  EXPECT_NEAR(e.max_px, 29.5, 1e-6);

  // Past max_searched_pixels a strided sample is searched: every pixel of the shifted edge is
  // 1.5 px from it, so the sample's figures are the whole image's; the far pixel may fall out.
  const EdgeDisplacement all =
      raycaster.edge_displacement(inverse, glm::dmat4(1), reference, tested, {});
  EXPECT_EQ(all.searched_pixels, all.differing_pixels);
  e = raycaster.edge_displacement(inverse, glm::dmat4(1), reference, tested,
                                  {.max_searched_pixels = 50});
  EXPECT_EQ(e.differing_pixels, all.differing_pixels);
  EXPECT_EQ(e.searched_pixels, 50u);
  EXPECT_EQ(e.measured_pixels + e.beyond_window + e.depth_ties + e.outside_display, 50u);
  EXPECT_GE(e.max_px, 1.5 - 1e-9);
  EXPECT_LE(e.max_px, 1.5 + 1e-6);

  EXPECT_THROW(raycaster.edge_displacement(inverse, glm::dmat4(1), reference,
                                           std::vector<std::uint32_t>(10), {}),
               InputError);
}

// The same rectangle through a pinhole GLC at the eye with the same 200×200 image: the camera's
// own rays cast at lattice points (no warp inverse applies) find the shifted edges where they
// are, within one lattice step: 1/32 px within the first pixel, 1/8 px beyond.
TEST(EdgeDisplacement, AGlcCameraIsMeasuredThroughItsOwnRays) {
  Scene scene;
  add_rectangle(scene, {-1, -0.5f}, {1, 0.5f}, -2);
  const ReferenceRaycaster raycaster(scene);
  // Frame: x right, y down, z forward (the eye's −z), its image plane 1 m ahead of the eye.
  GlcFrame frame;
  frame.origin = {0, 0, -1};
  frame.axes = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1));
  const PiecewiseGlc camera =
      single_glc(pinhole_glc(frame, {0, 0, -1}, {2, 2}, {200, 200}, "test", "camera"), {200, 200});
  constexpr double kZNear = 0.01;
  const std::vector<std::uint32_t> reference = raycaster.ids(camera, glm::dmat4(1), kZNear);
  for (int y = 0; y < 200; y += 7) {
    for (int x = 0; x < 200; x += 7) {
      ASSERT_EQ(reference[std::size_t(y) * 200 + x], expected_rectangle_id(x, y, 1))
          << x << "," << y;
    }
  }
  EdgeDisplacement e =
      raycaster.edge_displacement(camera, glm::dmat4(1), kZNear, reference, reference, {});
  EXPECT_EQ(e.differing_pixels, 0u);

  std::vector<std::uint32_t> tested(reference.size());
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      tested[std::size_t(y) * 200 + x] = x < 2 ? 0 : expected_rectangle_id(x - 2, y, 1);
    }
  }
  e = raycaster.edge_displacement(camera, glm::dmat4(1), kZNear, reference, tested, {});
  EXPECT_GT(e.differing_pixels, 4u * 50u);
  EXPECT_EQ(e.beyond_window, 0u);
  EXPECT_EQ(e.measured_pixels, e.differing_pixels);
  EXPECT_GE(e.max_px, 1.5 - 1e-9);
  EXPECT_LE(e.max_px, 1.5 + 1.0 / 8 + 1e-9);

  // 29.5 px off: beyond the 4 px window, and found with a wider one.
  tested[100 * 200 + 20] = 2;
  e = raycaster.edge_displacement(camera, glm::dmat4(1), kZNear, reference, tested, {});
  EXPECT_EQ(e.beyond_window, 1u);
  e = raycaster.edge_displacement(camera, glm::dmat4(1), kZNear, reference, tested,
                                  {.window_px = 32});
  EXPECT_EQ(e.beyond_window, 0u);
  EXPECT_NEAR(e.max_px, 29.5, 1.0 / 8 + 1e-9);

  EXPECT_THROW(raycaster.edge_displacement(camera, glm::dmat4(1), kZNear, reference,
                                           std::vector<std::uint32_t>(10), {}),
               InputError);
}

// A sliver: a rectangle 0.2 px tall, whose two triangles meet along a diagonal 100 px long. The
// reference image shows few of its pixel centres; a tested image that gives the diagonal's
// pixels to the other triangle, as a renderer moving the diagonal by a fraction of a pixel
// does, is tens of pixels off by the image-based distance and within a pixel by the exact one.
// A triangle drawn one pixel past its edge where that edge lies just outside the warp's coverage
// (as where facets straddle the coverage's edge): the warp's map goes on there, and the distance
// is measured through it. Searching covered positions only found the triangle nowhere.
TEST(EdgeDisplacement, EdgesJustPastTheCoverageAreFound) {
  Scene scene;
  // tan_x = x/100 − 1 at z = −2: the rectangles meet at x = 49.5 px.
  add_rectangle(scene, {-2, -1}, {-1.01f, 1}, -2);  // IDs 1, 2: x < 49.5
  add_rectangle(scene, {-1.01f, -1}, {2, 1}, -2);   // IDs 3, 4
  Warp warp = square_view();
  warp.grid_size = {3, 3};
  warp.offset_px.assign(9, glm::vec2(0));
  warp.coverage.assign(9, 1.0f);
  // The left column of nodes uncovered: coverage crosses 0.5 at x = 50 px.
  for (int j = 0; j < 3; ++j) warp.coverage[warp.node_index(0, j)] = 0;
  const ReferenceRaycaster raycaster(scene);
  const WarpInverse inverse(warp);
  const std::vector<std::uint32_t> reference = raycaster.ids(inverse, glm::dmat4(1));
  std::vector<std::uint32_t> tested = reference;
  for (int y = 60; y < 140; ++y) {
    const std::size_t at = std::size_t(y) * 200 + 50;
    ASSERT_GE(reference[at], 3u);
    ASSERT_EQ(reference[at - 1], 0u);  // uncovered
    // The left rectangle's triangle that the ray through (49, y + 0.5) meets.
    tested[at] = raycaster.id_along(glm::dvec3(0), {49.0 / 100 - 1, 1 - (y + 0.5) / 100, -1});
    ASSERT_TRUE(tested[at] == 1u || tested[at] == 2u);
  }
  const EdgeDisplacement e =
      raycaster.edge_displacement(inverse, glm::dmat4(1), reference, tested, {});
  EXPECT_EQ(e.differing_pixels, 80u);
  EXPECT_EQ(e.beyond_window, 0u);
  EXPECT_NEAR(e.max_px, 1.0, 1e-3);  // from the pixel centre 50.5 to the edge at 49.5
}

TEST(EdgeDisplacement, SliverIsMeasuredWhereItLies) {
  Scene scene;
  // tan_y in (0.0035, 0.0055) · 2 m: output rows y ∈ (99.45, 99.65), so only row 99's centres
  // (99.5) are inside; tan_x in (-0.5, 0.5): columns 50..149.
  add_rectangle(scene, {-1, 0.007f}, {1, 0.011f}, -2);
  const ReferenceRaycaster raycaster(scene);
  const WarpInverse inverse(square_view());
  const std::vector<std::uint32_t> reference = raycaster.ids(inverse, glm::dmat4(1));
  std::size_t first = 0, second = 0;
  for (const std::uint32_t id : reference) {
    first += id == 1;
    second += id == 2;
  }
  ASSERT_GT(first, 16u);
  ASSERT_GT(second, 16u);
  // Every pixel of the row given to triangle 1.
  std::vector<std::uint32_t> tested = reference;
  for (std::uint32_t& id : tested) {
    if (id == 2) id = 1;
  }
  const IdComparison image_based = compare_ids(reference, tested, {200, 200});
  const EdgeDisplacement exact =
      raycaster.edge_displacement(inverse, glm::dmat4(1), reference, tested, {});
  EXPECT_GT(image_based.max_edge_px, 10.0);
  EXPECT_EQ(exact.beyond_window, 0u);
  EXPECT_LT(exact.max_px, 0.5);
}

}  // namespace
}  // namespace facet::driver
