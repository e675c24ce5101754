// Facets: continuity across shared edges, the tolerance, the clip matrix and float32 error.
#include "facet/projection/facets.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include "facet/projection/errors.hpp"
#include "facet/projection/facet_error.hpp"
#include "test_displays.hpp"

namespace facet {
namespace {

// Every edge shared by two facets (the same two vertex indices) maps to the same pixels from both
// sides, within 1e-6 px worst case over 33 points per edge, in double.
double worst_shared_edge_gap(const FacetMesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> first_owner;
  double worst = 0;
  std::size_t shared = 0;
  for (std::uint32_t f = 0; f < mesh.facets.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t a = mesh.facets[f].vertex[k], b = mesh.facets[f].vertex[(k + 1) % 3];
      if (a > b) std::swap(a, b);
      auto [it, inserted] = first_owner.emplace(std::pair{a, b}, f);
      if (inserted) continue;
      ++shared;
      const Facet& other = mesh.facets[it->second];
      for (int m = 0; m <= 32; ++m) {
        const double u = m / 32.0;
        const glm::dvec3 X = (1 - u) * mesh.vertices[a].p_eye + u * mesh.vertices[b].p_eye;
        // Scale the point along its ray: the projection must not depend on the distance.
        const glm::dvec3 far_X = X * (1.0 + 1000.0 * u);
        worst = std::max(worst, glm::length(mesh.facets[f].project(far_X) - other.project(far_X)));
      }
    }
  }
  EXPECT_GT(shared, 0u);
  return worst;
}

TEST(Facets, SharedEdgesMapToTheSamePixels) {
  for (const auto& [name, warp] : test::displays_for_tolerance_tests()) {
    SCOPED_TRACE(name);
    for (const FacetLayout& layout :
         {FacetLayout{FacetTolerance{0.25}}, FacetLayout{FacetGrid{12, 9}}}) {
      const FacetMesh mesh = build_facets(warp, {layout});
      EXPECT_LE(worst_shared_edge_gap(mesh), 1e-6);
    }
  }
}

TEST(Facets, SeamOfA360CylinderIsContinuousModuloTheWidth) {
  const Warp warp = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200});
  const FacetMesh mesh = build_facets(warp, {FacetStrips{160}});
  ASSERT_EQ(mesh.facets.size(), 320u);
  // The first and the last strip both hold the seam direction (s = 0 and s = 1).
  const int columns = int(mesh.s_breaks.size()) - 1;
  const std::uint32_t first = mesh.cell_first_facet[0], last = mesh.cell_first_facet[columns - 1];
  const glm::dvec3 top = warp.p_eye_surface_from_st({0, 0}),
                   bottom = warp.p_eye_surface_from_st({0, 1});
  double worst = 0;
  for (int m = 0; m <= 32; ++m) {
    const glm::dvec3 X = top + (bottom - top) * (m / 32.0);
    auto on_seam = [&](std::uint32_t cell_first) {
      // Of the cell's two facets, the one whose pyramid holds the seam edge.
      for (std::uint32_t f = cell_first; f < cell_first + 2; ++f) {
        const Facet& facet = mesh.facets[f];
        if (std::min({glm::dot(facet.edge_normal[0], X), glm::dot(facet.edge_normal[1], X),
                      glm::dot(facet.edge_normal[2], X)}) > -1e-12) {
          return facet.project(X);
        }
      }
      ADD_FAILURE() << "seam point outside its cell's facets";
      return glm::dvec2(0.0);
    };
    const glm::dvec2 q_left = on_seam(first), q_right = on_seam(last);
    EXPECT_NEAR(q_left.x, 0.0, 1e-6);
    EXPECT_NEAR(q_right.x, 1600.0, 1e-6);
    worst = std::max(worst, std::abs(q_left.y - q_right.y));
  }
  EXPECT_LE(worst, 1e-6);
}

TEST(Facets, ToleranceIsMetOnEveryBase) {
  for (const auto& [name, warp] : test::displays_for_tolerance_tests()) {
    for (double tolerance : {1.0, 0.25, 0.05}) {
      SCOPED_TRACE(name + " at " + std::to_string(tolerance) + " px");
      const FacetMesh mesh = build_facets(warp, {FacetTolerance{tolerance}});
      const FacetError error = evaluate_facet_error(warp, mesh);
      EXPECT_LE(error.max_px, tolerance);  // worst case over dense samples
      EXPECT_LE(error.rms_px, error.max_px);
      EXPECT_EQ(error.missed_samples, 0u) << "a covered direction fell in no facet";
      // The builder should not be wastefully far below the tolerance either.
      EXPECT_GE(error.max_px, 0.5 * tolerance) << mesh.facets.size() << " facets";
      // The float32 matrices of a GPU add far less than the tolerance.
      EXPECT_LE(error.float32_max_px, 0.01);
    }
  }
}

// Layouts that would need more than max_cells are refused before the build, quickly: a tiny
// tolerance by its estimate from a 1 px build, grids and strips by their count.
TEST(Facets, LayoutsBeyondTheCellCapAreRefusedBeforeBuilding) {
  const Warp dome = Warp::analytic(BaseProjection::fisheye(180), {512, 512});
  FacetBuildOptions options;
  options.max_cells = 4096;
  for (const FacetLayout& layout :
       {FacetLayout(FacetTolerance{1e-9}), FacetLayout(FacetTolerance{1e-4}),
        FacetLayout(FacetGrid{65536, 1}), FacetLayout(FacetGrid{100, 100}),
        FacetLayout(FacetStrips{5000})}) {
    options.layout = layout;
    EXPECT_THROW(build_facets(dome, options), InputError) << layout.index();
  }
  // Within the cap they build: 1 px needs 240 cells here, 0.08 px (estimated from them) about
  // 3,000.
  options.layout = FacetTolerance{0.08};
  const FacetMesh mesh = build_facets(dome, options);
  EXPECT_LE(mesh.facets.size(), 2u * 4096u);
  options.layout = FacetGrid{64, 64};
  EXPECT_NO_THROW(build_facets(dome, options));
}

TEST(Facets, PerspectiveBaseIsExactWithTwoFacets) {
  const Warp warp = Warp::analytic(BaseProjection::perspective_fov(120, 90), {1920, 1080});
  const FacetMesh mesh = build_facets(warp, {FacetTolerance{0.05}});
  EXPECT_EQ(mesh.facets.size(), 2u);
  EXPECT_LE(evaluate_facet_error(warp, mesh).max_px, 1e-6);
}

TEST(Facets, SeedCylinderStripsArePlanarAndMatchTheirCount) {
  const Warp warp = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200});
  const FacetMesh mesh = build_facets(warp, {FacetStrips{160}});
  for (std::size_t cell = 0; cell < 160; ++cell) {
    const Facet& a = mesh.facets[2 * cell];
    const Facet& b = mesh.facets[2 * cell + 1];
    EXPECT_NEAR(glm::dot(a.n, b.n), 1.0, 1e-12);  // both halves of a strip share one plane
  }
  const FacetError error = evaluate_facet_error(warp, mesh);
  // A strip of w = 2.25° has its largest error at mid-width on the top and bottom rows: about
  // 0.116 px from the secant plane (1 − cos(w/2)) · 600 px plus the tan-versus-angle term.
  EXPECT_NEAR(error.max_px, 0.1155, 0.002);
}

TEST(Facets, GridModeGivesTwoFacetsPerCell) {
  const Warp warp = test::with_smooth_offsets(
      Warp::analytic(BaseProjection::perspective_fov(90, 70), {80, 60}), {5, 5}, 3);
  const FacetMesh mesh = build_facets(warp, {FacetGrid{80, 60}});
  EXPECT_EQ(mesh.facets.size(), 2u * 80 * 60);
  EXPECT_EQ(mesh.vertices.size(), 81u * 61);
}

TEST(Facets, ClipMatrixAgreesWithTheProjection) {
  const Warp warp = Warp::analytic(BaseProjection::fisheye(200), {1024, 1024});
  const FacetMesh mesh = build_facets(warp, {FacetGrid{16, 16}});
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> unit(0, 1);
  const double z_near = 0.05;
  for (std::uint32_t f = 0; f < mesh.facets.size(); f += 7) {
    const Facet& facet = mesh.facets[f];
    const glm::dmat4 clip_from_eye = facet.clip_from_eye(mesh.output_size, z_near);
    const auto p = mesh.corners(f);
    double a = unit(random), b = unit(random);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const double distance = 0.1 + 100 * unit(random);
    const glm::dvec3 X = distance * (p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]));
    const glm::dvec4 clip = clip_from_eye * glm::dvec4(X, 1);
    const glm::dvec2 q{(clip.x / clip.w + 1) / 2 * 1024, (1 - clip.y / clip.w) / 2 * 1024};
    EXPECT_LE(glm::length(q - facet.project(X)), 1e-9);
    const double depth = clip.z / clip.w;
    EXPECT_NEAR(depth, z_near / glm::dot(facet.n, X), 1e-12);
    EXPECT_GT(depth, 0);
    EXPECT_LE(depth, 1);
    for (const auto& plane : mesh.clip_planes(f)) EXPECT_GE(glm::dot(plane, X), 0);
  }
}

TEST(Facets, GuardBandIsTheRequestedPixelsOnEveryEdge) {
  // 40 strips of 25×800 px: thin facets. A scaling about the centroid sized for the short edge
  // (266.7 px from the centroid) moved the long ones (8.3 px from it) by 0.05·8.3/266.7 = 0.0016
  // px for a 0.05 px guard.
  const Warp warp = Warp::analytic(BaseProjection::cylindrical(-90, 90, 1, -1), {1000, 800});
  const FacetMesh mesh = build_facets(warp, {FacetStrips{40}});
  const double guard_px = 0.05;
  for (std::uint32_t f = 0; f < mesh.facets.size(); ++f) {
    const Facet& facet = mesh.facets[f];
    const auto planes = mesh.clip_planes(f, guard_px);
    // The chord-plane point that facet f shows at output position q.
    const glm::dmat3 M_eye_q = glm::inverse(facet.M_q_eye);
    const auto X_at = [&](glm::dvec2 q) {
      const glm::dvec3 X = M_eye_q * glm::dvec3(q, 1.0);
      return X * (facet.h / glm::dot(facet.n, X));
    };
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 a = mesh.vertices[facet.vertex[k]].q;
      const glm::dvec2 b = mesh.vertices[facet.vertex[(k + 1) % 3]].q;
      const glm::dvec2 c = mesh.vertices[facet.vertex[(k + 2) % 3]].q;
      glm::dvec2 outward{(b - a).y, -(b - a).x};
      outward = glm::normalize(outward);
      if (glm::dot(outward, c - a) > 0) outward = -outward;
      // Along the outward normal from three points of the edge, the guarded plane is crossed at
      // guard_px: plane·X is linear in q on the chord plane, so the crossing is one division.
      for (double along : {0.0, 0.5, 1.0}) {
        const glm::dvec2 q = a + along * (b - a);
        const double at_edge = glm::dot(planes[k], X_at(q));
        const double one_px_out = glm::dot(planes[k], X_at(q + outward));
        const double guard = at_edge / (at_edge - one_px_out);
        EXPECT_NEAR(guard, guard_px, 1e-6) << "facet " << f << " edge " << k << " at " << along;
      }
    }
  }
}

// Conformity of a bisection mesh: no vertex lies inside another facet's edge, and no edge has more
// than two facets. Bisection adds vertices at edge midpoints only, so a hanging vertex is a vertex
// at some edge's midpoint. On a 360° base s is taken modulo 1, so the seam's sides are one edge.
struct Conformity {
  std::size_t hanging_vertices = 0, overused_edges = 0;
};
Conformity conformity(const FacetMesh& mesh, bool wraps) {
  const auto canonical = [&](glm::dvec2 st) {
    if (wraps && st.x >= 1.0) st.x -= 1.0;
    return std::pair{st.x, st.y};
  };
  std::set<std::pair<double, double>> vertices;
  for (const FacetVertex& v : mesh.vertices) vertices.insert(canonical(v.st));
  std::map<std::pair<std::pair<double, double>, std::pair<double, double>>, int> uses;
  Conformity result;
  for (const Facet& facet : mesh.facets) {
    for (int k = 0; k < 3; ++k) {
      const glm::dvec2 a = mesh.vertices[facet.vertex[k]].st;
      const glm::dvec2 b = mesh.vertices[facet.vertex[(k + 1) % 3]].st;
      if (vertices.count(canonical((a + b) / 2.0))) ++result.hanging_vertices;
      const auto ca = canonical(a), cb = canonical(b);
      if (++uses[{std::min(ca, cb), std::max(ca, cb)}] == 3) ++result.overused_edges;
    }
  }
  return result;
}

TEST(Facets, BisectionMeetsTheToleranceWithoutHangingVertices) {
  for (const auto& [name, warp] : test::displays_for_tolerance_tests()) {
    for (double tolerance : {1.0, 0.25}) {
      SCOPED_TRACE(name + " at " + std::to_string(tolerance) + " px");
      FacetTolerance layout{tolerance};
      layout.builder = FacetTolerance::Builder::bisection;
      const FacetMesh mesh = build_facets(warp, {layout});
      EXPECT_TRUE(mesh.s_breaks.empty()) << "a bisection mesh has no tensor layout";
      const FacetError error = evaluate_facet_error(warp, mesh);
      EXPECT_LE(error.max_px, tolerance);  // worst case over dense samples
      EXPECT_EQ(error.missed_samples, 0u) << "a covered direction fell in no facet";
      // Each bisection shrinks a facet's error about fourfold; the worst facet stays above that.
      EXPECT_GE(error.max_px, 0.25 * tolerance) << mesh.facets.size() << " facets";
      EXPECT_LE(error.float32_max_px, 0.01);
      const Conformity c = conformity(mesh, warp.base.wraps_horizontally());
      EXPECT_EQ(c.hanging_vertices, 0u);
      EXPECT_EQ(c.overused_edges, 0u);
      EXPECT_LE(worst_shared_edge_gap(mesh), 1e-6);
    }
  }
}

// A 180° dome master whose offset map bends sharply in one place only: a 6 px bump of 10 px
// radius (Gaussian) at output pixel (190, 70).
Warp dome_with_one_bump() {
  Warp warp = Warp::analytic(BaseProjection::fisheye(180), {256, 256}, {129, 129});
  for (int j = 0; j < warp.grid_size.y; ++j) {
    for (int i = 0; i < warp.grid_size.x; ++i) {
      const glm::dvec2 q{256.0 * i / 128, 256.0 * j / 128};
      const double r2 = glm::dot(q - glm::dvec2(190, 70), q - glm::dvec2(190, 70));
      warp.offset_px[warp.node_index(i, j)] += glm::vec2(float(6 * std::exp(-r2 / 100)), 0.0f);
    }
  }
  return warp;
}

TEST(Facets, TheDefaultBuilderKeepsTheLayoutWithFewerFacets) {
  struct Counts {
    std::size_t tensor, bisection, fewest;
  };
  const auto counts = [](const std::string& name, const Warp& warp) {
    const auto count = [&](FacetTolerance::Builder builder) {
      FacetTolerance layout{0.25};
      layout.builder = builder;
      return build_facets(warp, {layout}).facets.size();
    };
    const Counts c{count(FacetTolerance::Builder::tensor),
                   count(FacetTolerance::Builder::bisection),
                   count(FacetTolerance::Builder::fewest)};
    std::printf("%s at 0.25 px: tensor %zu, bisection %zu facets\n", name.c_str(), c.tensor,
                c.bisection);
    return c;
  };
  // The cylinder's error does not change along its height: tall tensor strips follow it.
  const Counts cylinder =
      counts("cylinder 1600x1200",
             Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200}));
  EXPECT_LT(cylinder.tensor, cylinder.bisection);
  EXPECT_EQ(cylinder.fewest, cylinder.tensor);
  // A bump is hard in one place: a tensor grid refines whole rows and columns through it.
  const Counts bump = counts("dome with one bump", dome_with_one_bump());
  EXPECT_LT(bump.bisection, bump.tensor);
  EXPECT_EQ(bump.fewest, bump.bisection);
}

TEST(Facets, ImpossibleLayoutsAreRejected) {
  const Warp cylinder = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200});
  EXPECT_THROW(build_facets(cylinder, {FacetStrips{2}}), InputError);  // 180° strips
  EXPECT_THROW(build_facets(cylinder, {FacetStrips{0}}), InputError);
  EXPECT_THROW(build_facets(cylinder, {FacetTolerance{-1}}), InputError);
  EXPECT_THROW(build_facets(cylinder, {FacetTolerance{NAN}}), InputError);
  // A tolerance that needs more cells than allowed gives a clear error, not a runaway build.
  EXPECT_THROW(build_facets(cylinder, {FacetTolerance{1e-4}, 64}), InputError);
  for (auto builder : {FacetTolerance::Builder::tensor, FacetTolerance::Builder::bisection}) {
    FacetTolerance layout{1e-4};
    layout.builder = builder;
    EXPECT_THROW(build_facets(cylinder, {layout, 64}), InputError);
  }
}

}  // namespace
}  // namespace facet
