// The CPU coverage reference: conservative against dense point sampling, over 10^5 triangles of
// every size and distance, through the eye, through the axis and partly behind the eye.
#include "facet/projection/coverage.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "facet/projection/errors.hpp"
#include "facet/projection/facets.hpp"
#include "random_geometry.hpp"

namespace facet {
namespace {

using Triangle = std::array<glm::dvec3, 3>;

using test::log_uniform;
using test::random_unit;

// Sizes 1e-4..1e3 m at distances 1e-3..1e6 m; one in 16 through the eye, one in 16 through the
// vertical (cylinder) axis.
Triangle random_triangle(std::mt19937_64& random, int k) {
  const double size = log_uniform(random, 1e-4, 1e3);
  glm::dvec3 centre = log_uniform(random, 1e-3, 1e6) * random_unit(random);
  if (k % 16 == 0) centre = glm::dvec3(0.0);
  if (k % 16 == 1) centre = glm::dvec3(0.0, centre.y, 0.0);
  Triangle t;
  for (auto& p : t) p = centre + size * random_unit(random);
  if (k % 16 == 0) {
    // Make the eye lie inside the triangle: flip the third vertex to the far side of the origin.
    t[2] = -(t[0] + t[1]) * 0.5 * (1.0 + std::uniform_real_distribution<double>(0.1, 2)(random));
  }
  return t;
}

struct Stats {
  std::size_t triangles = 0, listed = 0, sampled = 0, misses = 0;
};

Stats check_conservative(const FacetMesh& mesh, int triangle_count, std::uint64_t seed) {
  const CoverageIndex index(mesh);
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  Stats stats;
  std::vector<std::uint32_t> listed, sampled;
  for (int k = 0; k < triangle_count; ++k) {
    const Triangle t = random_triangle(random, k);
    listed.clear();
    index.query(t, listed);
    sampled.clear();
    auto sample = [&](double a, double b) {
      const glm::dvec3 X = t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]);
      if (glm::length(X) < 1e-9 * glm::length(t[0])) return;
      if (auto f = index.locate(X)) sampled.push_back(*f);
    };
    constexpr int n = 8;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) sample(double(i) / n, double(j) / n);
    }
    for (int r = 0; r < 16; ++r) {
      double a = unit(random), b = unit(random);
      if (a + b > 1) a = 1 - a, b = 1 - b;
      sample(a, b);
    }
    std::sort(sampled.begin(), sampled.end());
    sampled.erase(std::unique(sampled.begin(), sampled.end()), sampled.end());
    for (std::uint32_t f : sampled) {
      if (!std::binary_search(listed.begin(), listed.end(), f)) {
        ++stats.misses;
        if (stats.misses < 5) {
          ADD_FAILURE() << "triangle " << k << " misses facet " << f << ": (" << t[0].x << ", "
                        << t[0].y << ", " << t[0].z << ") (" << t[1].x << ", " << t[1].y << ", "
                        << t[1].z << ") (" << t[2].x << ", " << t[2].y << ", " << t[2].z << ")";
        }
      }
    }
    ++stats.triangles;
    stats.listed += listed.size();
    stats.sampled += sampled.size();
  }
  return stats;
}

TEST(Coverage, NeverMissesASampledFacetOnA360Cylinder) {
  const Warp warp = Warp::analytic(BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200});
  const FacetMesh mesh = build_facets(warp, {FacetTolerance{0.25}});
  const Stats stats = check_conservative(mesh, 50000, 11);
  EXPECT_EQ(stats.misses, 0u);
  // Tightness, reported: facets listed per facet that sampling found.
  std::printf("cylinder: %zu triangles, %.3f listed per sampled facet\n", stats.triangles,
              double(stats.listed) / double(std::max<std::size_t>(1, stats.sampled)));
}

TEST(Coverage, NeverMissesASampledFacetOnAFisheyeDome) {
  const Warp warp = Warp::analytic(BaseProjection::fisheye(200), {1024, 1024});
  const FacetMesh mesh = build_facets(warp, {FacetGrid{16, 16}});
  const Stats stats = check_conservative(mesh, 50000, 12);
  EXPECT_EQ(stats.misses, 0u);
  std::printf("dome: %zu triangles, %.3f listed per sampled facet\n", stats.triangles,
              double(stats.listed) / double(std::max<std::size_t>(1, stats.sampled)));
}

TEST(Coverage, TriangleBehindAPerspectiveDisplayCoversNothing) {
  const Warp warp = Warp::analytic(BaseProjection::perspective_fov(90, 60), {640, 480});
  const FacetMesh mesh = build_facets(warp, {FacetGrid{4, 4}});
  const CoverageIndex index(mesh);
  std::vector<std::uint32_t> facets;
  index.query({glm::dvec3(-1, -1, 2), glm::dvec3(1, -1, 2), glm::dvec3(0, 1, 2)}, facets);
  EXPECT_TRUE(facets.empty());
  // Partly behind: only the part in front counts, and it reaches the centre cells.
  index.query({glm::dvec3(-0.1, -0.1, -5), glm::dvec3(0.1, -0.1, -5), glm::dvec3(0, 0.1, 5)},
              facets);
  EXPECT_FALSE(facets.empty());
  // Seen edge-on through the eye, a triangle in the plane x = 0 covers only the centre column.
  facets.clear();
  index.query({glm::dvec3(0, -1, -1), glm::dvec3(0, 1, -1), glm::dvec3(0, 0, 1)}, facets);
  for (std::uint32_t f : facets) {
    const auto p = mesh.corners(f);
    const double min_x = std::min({p[0].x, p[1].x, p[2].x}),
                 max_x = std::max({p[0].x, p[1].x, p[2].x});
    EXPECT_LE(min_x, 1e-3);
    EXPECT_GE(max_x, -1e-3);
  }
}

TEST(Coverage, BackFacesAreCulledOnRequest) {
  const Warp warp = Warp::analytic(BaseProjection::perspective_fov(90, 60), {640, 480});
  const FacetMesh mesh = build_facets(warp, {FacetGrid{4, 4}});
  const CoverageIndex index(mesh);
  const Triangle front{glm::dvec3(-1, -1, -3), glm::dvec3(1, -1, -3), glm::dvec3(0, 1, -3)};
  const Triangle back{front[0], front[2], front[1]};
  std::vector<std::uint32_t> facets;
  index.query(front, facets, true);
  EXPECT_FALSE(facets.empty());
  facets.clear();
  index.query(back, facets, true);
  EXPECT_TRUE(facets.empty());
  index.query(back, facets, false);
  EXPECT_FALSE(facets.empty());
}

TEST(Coverage, NonFiniteTriangleIsRejected) {
  const Warp warp = Warp::analytic(BaseProjection::fisheye(180), {256, 256});
  const FacetMesh mesh = build_facets(warp, {FacetGrid{4, 4}});
  const CoverageIndex index(mesh);
  std::vector<std::uint32_t> facets;
  EXPECT_THROW(
      index.query({glm::dvec3(0, 0, -1), glm::dvec3(NAN, 0, -1), glm::dvec3(0, 1, -1)}, facets),
      InputError);
  EXPECT_THROW(
      index.query({glm::dvec3(0, 0, -1), glm::dvec3(1, 0, -1), glm::dvec3(0, INFINITY, -1)},
                  facets),
      InputError);
}

}  // namespace
}  // namespace facet
