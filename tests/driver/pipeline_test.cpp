// The facet replication pipelines on llvmpipe at small sizes: GPU coverage against the CPU
// reference (CoverageIndex), the modern and seed pipelines against each other, naive multi-pass
// against both, seams, reuse, and hostile triangles.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>
#include <random>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "facet/driver/city.hpp"
#include "facet/driver/display_outputs.hpp"
#include "facet/driver/facet_gpu.hpp"
#include "facet/driver/gpu_scene.hpp"
#include "facet/driver/render_method.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/projection/coverage.hpp"
#include "facet/projection/errors.hpp"
#include "gl_test_context.hpp"
#include "test_scenes.hpp"

namespace facet::driver {
namespace {

const glm::ivec2 kCylinderSize{256, 192};
const glm::ivec2 kDomeSize{192, 192};

std::vector<OutputSpec> cylinder() {
  return load_display_outputs("builtin:cylinder360", kCylinderSize);
}
std::vector<OutputSpec> dome() { return load_display_outputs("builtin:dome180", kDomeSize); }

RenderSettings strips(int count) {
  RenderSettings settings;
  settings.facets.layout = FacetStrips{count};
  return settings;
}

using facet::test::background_sphere;

Scene small_city() {
  CityOptions options;
  options.blocks_per_side = 1;
  options.texture_size = 8;
  return build_city(options);
}

glm::dmat4 city_view(double t) {
  CityOptions options;
  options.blocks_per_side = 1;
  return glm::inverse(CityCameraPath(options).T_world_eye(t));
}

struct Rendered {
  std::vector<std::vector<std::uint32_t>> ids;  // per output
  RenderStats stats;
};

Rendered render(std::string_view method, const Scene& scene, const std::vector<OutputSpec>& outputs,
                const RenderSettings& settings, const glm::dmat4& T_eye_world) {
  const GpuScene gpu = upload_scene(scene);
  auto renderer = make_render_method(method);
  renderer->prepare(scene, gpu, outputs, settings);
  std::vector<OutputTarget> targets;
  for (const auto& output : outputs)
    targets.push_back(OutputTarget::create(output.warp.output_size));
  Rendered result;
  result.stats = renderer->render(T_eye_world, targets);
  for (const auto& target : targets) result.ids.push_back(target.read_ids());
  check_gl_error("render");
  return result;
}

std::size_t count_value(const std::vector<std::uint32_t>& ids, std::uint32_t value) {
  return std::size_t(std::count(ids.begin(), ids.end(), value));
}

TEST(Pipeline, MethodNamesAndUnknownMethod) {
  const auto names = render_method_names();
  ASSERT_EQ(names.size(), 9u);
  EXPECT_EQ(names[0], "facets");
  EXPECT_THROW(make_render_method("bogus"), InputError);
  for (std::string_view name : names) EXPECT_EQ(make_render_method(name)->name(), name);
}

TEST(Pipeline, TriangleBaseCountsObjectsInOrder) {
  const Scene scene = small_city();
  const auto base = scene_triangle_base(scene);
  ASSERT_EQ(base.size(), scene.objects.size() + 1);
  EXPECT_EQ(base.front(), 0u);
  EXPECT_EQ(base.back(), scene.triangle_count());
}

TEST(Pipeline, BadDisplayIsInputError) {
  EXPECT_THROW(load_display_outputs("builtin:nothing", std::nullopt), InputError);
  EXPECT_THROW(load_display_outputs("missing.warp.exr", std::nullopt), InputError);
  const auto outputs = load_display_outputs("builtin:dome180", std::nullopt);
  ASSERT_EQ(outputs.size(), 1u);
  EXPECT_EQ(outputs[0].warp.output_size, glm::ivec2(2048, 2048));
  // Documented orientation: the image centre looks up (+y), the bottom edge to the front (-z).
  const glm::dvec3 centre = outputs[0].warp.v_eye_from_st({0.5, 0.5});
  EXPECT_NEAR(centre.y, 1.0, 1e-12);
  const glm::dvec3 bottom = outputs[0].warp.v_eye_from_st({0.5, 1.0});
  EXPECT_NEAR(bottom.z, -1.0, 1e-12);
}

// Random triangles around the eye, all sizes, some through or behind the eye, checked against
// CoverageIndex::query on the same (float) corners.
// A cylinder cell's two facets share a chord plane and a projection: one convex quad, whose
// guarded pyramid lies in the union of its facets' (the grid lists it where they are listed).
// A dome cell's facets do not, and stay apart.
TEST(FacetPieces, CoplanarCellsBecomeConvexQuads) {
  FacetBuildOptions forty;
  forty.layout = FacetStrips{40};
  const FacetMesh cylinder_mesh = build_facets(cylinder()[0].warp, forty);
  const FacetPieces pieces = make_facet_pieces(cylinder_mesh, true);
  ASSERT_EQ(pieces.facet_count, 80u);
  ASSERT_EQ(pieces.quads.size(), 40u);
  EXPECT_EQ(pieces.size(), 120u);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::uint32_t p = pieces.facet_count; p < pieces.size(); ++p) {
    ASSERT_TRUE(pieces.drawn(p));
    const auto& planes = pieces.planes[p];
    const auto& corners = pieces.corners[p];
    for (const std::uint32_t f : pieces.quads[p - pieces.facet_count]) {
      EXPECT_EQ(pieces.piece_of_facet[f], p);
      EXPECT_FALSE(pieces.drawn(f));
      for (const glm::dvec3& c : cylinder_mesh.corners(f))
        for (const glm::dvec3& n : planes) EXPECT_GT(glm::dot(n, glm::normalize(c)), 0.0);
    }
    for (int k = 0; k < 4; ++k) {
      // Corner k is where planes k and k + 1 meet, inside the other two.
      EXPECT_NEAR(glm::dot(planes[k], corners[k]), 0.0, 1e-12);
      EXPECT_NEAR(glm::dot(planes[(k + 1) % 4], corners[k]), 0.0, 1e-12);
      EXPECT_GT(glm::dot(planes[(k + 2) % 4], corners[k]), 0.0);
      EXPECT_GT(glm::dot(planes[(k + 3) % 4], corners[k]), 0.0);
    }
    const auto& quad = pieces.quads[p - pieces.facet_count];
    const auto a = cylinder_mesh.clip_planes(quad[0]), b = cylinder_mesh.clip_planes(quad[1]);
    const auto inside = [](const auto& cone, const glm::dvec3& v) {
      for (const glm::dvec3& n : cone)
        if (glm::dot(n, v) < -1e-12) return false;
      return true;
    };
    for (int k = 0; k < 200; ++k) {
      double w[4], sum = 0;
      for (double& x : w) sum += x = unit(random);
      glm::dvec3 v(0.0);
      for (int c = 0; c < 4; ++c) v += w[c] / sum * corners[c];
      ASSERT_TRUE(inside(planes, v));
      EXPECT_TRUE(inside(a, v) || inside(b, v)) << "piece " << p;
    }
  }
  EXPECT_EQ(make_facet_pieces(cylinder_mesh, false).size(), 80u);
  const FacetMesh dome_mesh = build_facets(dome()[0].warp, FacetBuildOptions{});
  const FacetPieces dome_pieces = make_facet_pieces(dome_mesh, true);
  EXPECT_TRUE(dome_pieces.quads.empty());
  EXPECT_EQ(dome_pieces.size(), dome_mesh.facets.size());
}

// pack_coverage_grid starts the per-piece bucket ranges and pyramid corners on a texel of the
// RGBA32UI view (replication_lib.comp's grid_vec4), and they hold what the grid and the pieces
// say: each piece's corners as float bits, and a range for each piece the grid lists.
TEST(FacetPieces, PackedGridRecordsStartOnATexel) {
  FacetBuildOptions forty, coarse;
  forty.layout = FacetStrips{40};
  coarse.layout = FacetTolerance{2.0};
  // The dome4 projector's bisection layout has uniform buckets.
  const auto projector = load_display_outputs(
      std::string(FACET_SOURCE_DIR) + "/configs/displays/dome4/display.json", std::nullopt);
  for (const auto& [name, outputs, options] :
       {std::tuple{"cylinder strips", cylinder(), forty}, std::tuple{"dome 2 px", dome(), coarse},
        std::tuple{"dome4 projector 2 px", projector, coarse}}) {
    const Warp& warp = outputs[0].warp;
    const FacetMesh mesh = build_facets(warp, options);
    const CoverageGrid grid(mesh, warp.base, warp.R_eye_base);
    const FacetPieces pieces = make_facet_pieces(mesh, true);
    if (std::string_view(name).starts_with("dome4")) {
      EXPECT_FALSE(grid.cell_buckets()) << name;
    }
    const std::vector<std::uint32_t> words = pack_coverage_grid(grid, pieces);
    ASSERT_GE(words.size(), kGridHeaderWords) << name;
    const std::uint32_t ranges_at = words[11], corners_at = words[21];
    EXPECT_EQ(ranges_at % 4, 0u) << name;
    EXPECT_EQ(corners_at % 4, 0u) << name;
    ASSERT_LE(std::size_t(corners_at) + 12 * pieces.size(), words.size()) << name;
    for (std::uint32_t p = 0; p < pieces.size(); ++p) {
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 3; ++k)
          EXPECT_EQ(words[corners_at + 12 * p + 3 * c + k],
                    std::bit_cast<std::uint32_t>(float(pieces.corners[p][c][k])))
              << name << " piece " << p;
    }
    // Bucket b lists pieces words[listed_at + m] for m in [words[first_at + b], words[first_at +
    // b + 1]); the range of each piece listed there holds the bucket, and every drawn piece is
    // listed somewhere.
    const std::uint32_t columns = words[2], rows = words[3];
    const std::uint32_t first_at = words[9], listed_at = words[10];
    std::size_t listings = 0;
    for (std::uint32_t b = 0; b < columns * rows; ++b) {
      for (std::uint32_t m = words[first_at + b]; m < words[first_at + b + 1]; ++m) {
        const std::uint32_t p = words[listed_at + m];
        const std::uint32_t i = b % columns, j = b / columns;
        const std::uint32_t* range = &words[ranges_at + 4 * p];  // column, row, columns, rows
        const std::uint32_t column_offset =
            grid.periodic() ? (i + columns - range[0]) % columns : i - range[0];
        EXPECT_TRUE(j >= range[1] && j - range[1] < range[3] && column_offset < range[2])
            << name << " piece " << p << " listed in bucket " << b;
        ++listings;
      }
    }
    std::size_t drawn = 0;
    for (std::uint32_t p = 0; p < pieces.size(); ++p) drawn += pieces.drawn(p) ? 1 : 0;
    EXPECT_GE(listings, drawn) << name;
    std::printf("%s: %s buckets %ux%u, %zu listings of %u pieces\n", name,
                grid.cell_buckets() ? "cell" : "uniform", columns, rows, listings, pieces.size());
  }
}

// A sphere inside one piece and clear of the others takes that piece alone: a small one in the
// middle of a cylinder quad or of a dome facet; none when it straddles two pieces, is large or
// holds the eye.
TEST(Pipeline, SolePieceOfASphere) {
  test::shared_context();
  RenderSettings quarter_px;
  quarter_px.facets.layout = FacetTolerance{0.25};
  const FacetSet cylinder_set = FacetSet::build(cylinder()[0].warp, quarter_px.facets, 0.05);
  const FacetPieces& pieces = cylinder_set.pieces;
  ASSERT_TRUE(cylinder_set.grid.cell_buckets());
  ASSERT_FALSE(pieces.quads.empty());
  for (std::uint32_t p = pieces.facet_count; p < pieces.size(); ++p) {
    glm::dvec3 middle(0.0);
    for (const glm::dvec3& c : pieces.corners[p]) middle += c;
    EXPECT_EQ(sole_piece_of_sphere(cylinder_set, 50.0 * glm::normalize(middle), 0.01), p);
    // On the edge shared with the next quad round the cylinder.
    const glm::dvec3 edge = glm::normalize(pieces.corners[p][0] + pieces.corners[p][1]);
    EXPECT_EQ(sole_piece_of_sphere(cylinder_set, 50.0 * edge, 0.01), kNoPiece) << p;
    EXPECT_EQ(sole_piece_of_sphere(cylinder_set, 50.0 * glm::normalize(middle), 10.0), kNoPiece);
  }
  EXPECT_EQ(sole_piece_of_sphere(cylinder_set, glm::dvec3(0, 0, -1), 2.0), kNoPiece);
  const FacetSet dome_set = FacetSet::build(dome()[0].warp, quarter_px.facets, 0.05);
  ASSERT_TRUE(dome_set.grid.cell_buckets());
  std::size_t found = 0;
  for (std::uint32_t f = 0; f < dome_set.pieces.size(); f += 7) {
    glm::dvec3 middle(0.0);
    for (const glm::dvec3& c : dome_set.mesh.corners(f)) middle += glm::normalize(c);
    const std::uint32_t sole = sole_piece_of_sphere(dome_set, 20.0 * glm::normalize(middle), 1e-3);
    EXPECT_EQ(sole, f);
    found += sole == f;
  }
  EXPECT_GT(found, 0u);
}

// Distance (metres) from `c` to the convex cone {X : n·X >= 0 for each plane n} through the
// eye: the nearest of the point itself, its projections on each face and on each edge ray, and
// the apex, among those inside the cone.
double distance_to_cone(const glm::dvec3& c, std::span<const glm::dvec3> planes) {
  const auto in_cone = [&](const glm::dvec3& x) {
    for (const glm::dvec3& n : planes)
      if (glm::dot(n, x) < -1e-9 * glm::length(n) * std::max(1.0, glm::length(x))) return false;
    return true;
  };
  if (in_cone(c)) return 0;
  double best = glm::length(c);  // the apex
  for (const glm::dvec3& n : planes) {
    const glm::dvec3 x = c - glm::dot(n, c) / glm::dot(n, n) * n;
    if (in_cone(x)) best = std::min(best, glm::length(c - x));
  }
  for (std::size_t i = 0; i < planes.size(); ++i)
    for (std::size_t j = i + 1; j < planes.size(); ++j) {
      const glm::dvec3 e = glm::cross(planes[i], planes[j]);
      if (glm::dot(e, e) == 0) continue;
      for (const double sign : {1.0, -1.0}) {
        const glm::dvec3 x = std::max(0.0, glm::dot(c, sign * e)) / glm::dot(e, e) * sign * e;
        if (in_cone(x)) best = std::min(best, glm::length(c - x));
      }
    }
  return best;
}

// Object culling against every facet and piece measured exactly (distance_to_cone): a sphere
// that meets a facet's guarded pyramid is never culled (sphere_may_meet_facets walks the
// hierarchy, pruned by cone angles), and sole_piece_of_sphere (the grid's nearby cells) names a
// piece only when the sphere lies inside it and meets no other piece in use, on the cylinder and
// the dome. How often each answers more loosely than the exact test is printed.
TEST(Pipeline, ObjectCullingIsConservativeAgainstExactDistances) {
  test::shared_context();
  RenderSettings quarter_px;
  quarter_px.facets.layout = FacetTolerance{0.25};
  std::mt19937 random(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const auto& [name, warp] :
       {std::pair{"cylinder", cylinder()[0].warp}, std::pair{"dome", dome()[0].warp}}) {
    const FacetSet set = FacetSet::build(warp, quarter_px.facets, 0.05);
    const auto& facet_planes = set.index.planes();
    const FacetPieces& pieces = set.pieces;
    // The pieces in use: a facet merged into a quad is drawn as that quad.
    std::vector<std::uint32_t> used(pieces.piece_of_facet.begin(), pieces.piece_of_facet.end());
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    constexpr int kSpheres = 3000;
    std::size_t meets = 0, kept_missing = 0, sole_named = 0, sole_possible = 0;
    for (int k = 0; k < kSpheres; ++k) {
      glm::dvec3 v(unit(random), unit(random), unit(random));
      if (glm::length(v) < 1e-3) v = glm::dvec3(0, 0, 1);
      const glm::dvec3 centre = (5.0 + 45.0 * (unit(random) + 1) / 2) * glm::normalize(v);
      const double radius = std::pow(10.0, -3.0 + 3.7 * (unit(random) + 1) / 2);  // 1 mm to 5 m
      bool any = false;
      for (const auto& planes : facet_planes)
        any = any || distance_to_cone(centre, planes) <= radius;
      const bool kept = sphere_may_meet_facets(set, centre, radius);
      if (any) {
        ASSERT_TRUE(kept) << name << " culled a sphere that meets a facet: centre " << centre.x
                          << "," << centre.y << "," << centre.z << " radius " << radius;
      }
      meets += any;
      kept_missing += kept && !any;
      std::vector<std::uint32_t> meeting;
      for (const std::uint32_t p : used)
        if (distance_to_cone(centre, pieces.planes[p]) <= radius) meeting.push_back(p);
      const auto holds = [&](std::uint32_t p) {
        for (const glm::dvec3& plane : pieces.planes[p])
          if (glm::dot(glm::normalize(plane), centre) < radius) return false;
        return true;
      };
      const std::uint32_t sole = sole_piece_of_sphere(set, centre, radius);
      if (sole != kNoPiece) {
        ASSERT_TRUE(holds(sole)) << name << ": piece " << sole << " does not hold the sphere";
        ASSERT_EQ(meeting, std::vector<std::uint32_t>{sole})
            << name << ": the sphere meets other pieces than " << sole;
      }
      sole_named += sole != kNoPiece;
      sole_possible += meeting.size() == 1 && holds(meeting[0]);
    }
    std::printf(
        "%s: %zu of %d spheres meet a facet, %zu more kept; a sole piece named for %zu of the "
        "%zu that have one\n",
        name, meets, kSpheres, kept_missing, sole_named, sole_possible);
    EXPECT_GT(meets, std::size_t(kSpheres / 4)) << name;
    EXPECT_GT(sole_named, sole_possible / 2) << name;
  }
}

// Clusters cover each primitive with consecutive runs of at most kClusterTriangles triangles
// whose IDs continue the primitive's, and on the city most of them face one way.
TEST(Pipeline, ClusterRecordsKeepTheTriangleIds) {
  const Scene city = build_city();
  const std::vector<GpuRecord> whole = make_records(city);
  const std::vector<GpuRecord> clusters = make_cluster_records(city);
  ASSERT_GT(clusters.size(), whole.size());
  std::size_t c = 0, one_way = 0;
  for (const GpuRecord& record : whole) {
    std::uint32_t covered = 0;
    while (covered < record.triangle_count) {
      ASSERT_LT(c, clusters.size());
      const GpuRecord& cluster = clusters[c++];
      EXPECT_EQ(cluster.first_index, record.first_index + 3 * covered);
      EXPECT_EQ(cluster.first_id, record.first_id + covered);
      EXPECT_EQ(cluster.object, record.object);
      EXPECT_EQ(cluster.material, record.material);
      EXPECT_GE(cluster.triangle_count, 1u);
      EXPECT_LE(cluster.triangle_count, kClusterTriangles);
      const ClusterBounds bounds = cluster_bounds(city, cluster);
      one_way += bounds.normal_spread_sin <= std::sin(glm::radians(60.0));
      covered += cluster.triangle_count;
    }
    EXPECT_EQ(covered, record.triangle_count);
  }
  EXPECT_EQ(c, clusters.size());
  std::printf("city: %zu records, %zu clusters, %zu with normals within 60 degrees of their axis\n",
              whole.size(), clusters.size(), one_way);
  EXPECT_GT(2 * one_way, clusters.size());
}

// cluster_bounds holds every corner in its sphere and every normal in its cone, and
// cluster_faces_away claims a cluster only when each of its triangles has every corner p with
// dot(normal, p - eye) > 0, which pass 1 culls as a back face: random clusters of random spread
// seen from random eyes, and the city's clusters seen along its camera path, all checked in
// double per triangle.
TEST(Pipeline, ClusterCullingOnlyTakesBackFaces) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto random_unit = [&] {
    glm::dvec3 v(unit(random), unit(random), unit(random));
    return glm::length(v) < 1e-3 ? glm::dvec3(0, 0, 1) : glm::normalize(v);
  };
  // Every triangle of `record` faces away from `eye` at each of its corners.
  const auto all_face_away = [](const Scene& scene, const GpuRecord& record,
                                const glm::dvec3& eye) {
    for (std::uint32_t t = 0; t < record.triangle_count; ++t) {
      glm::dvec3 p[3];
      for (int c = 0; c < 3; ++c)
        p[c] = glm::dvec3(scene.positions[scene.indices[record.first_index + 3 * t + c]]);
      const glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
      for (const glm::dvec3& q : p)
        if (!(glm::dot(n, q - eye) > 0)) return false;
    }
    return true;
  };
  const auto check_bounds = [](const Scene& scene, const GpuRecord& record,
                               const ClusterBounds& bounds) {
    for (std::uint32_t t = 0; t < record.triangle_count; ++t) {
      glm::dvec3 p[3];
      for (int c = 0; c < 3; ++c) {
        p[c] = glm::dvec3(scene.positions[scene.indices[record.first_index + 3 * t + c]]);
        ASSERT_LE(glm::length(p[c] - bounds.centre), bounds.radius * (1 + 1e-12));
      }
      if (bounds.normal_spread_sin > 1) continue;
      const glm::dvec3 n = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
      const double cos_spread = std::sqrt(1 - bounds.normal_spread_sin * bounds.normal_spread_sin);
      ASSERT_GE(glm::dot(n, bounds.normal_axis), cos_spread - 1e-12);
    }
  };
  std::size_t claimed = 0, random_eyes = 0;
  for (int k = 0; k < 400; ++k) {
    // A cluster of 16 triangles about a random point, their normals within a random spread of
    // a random axis.
    Scene scene;
    const glm::dvec3 centre = 20.0 * random_unit(), axis = random_unit();
    const double spread = std::abs(unit(random)) * 1.2, size = std::pow(10.0, unit(random));
    for (int t = 0; t < 16; ++t) {
      glm::dvec3 normal = axis;
      for (int tries = 0; tries < 100; ++tries) {
        normal = random_unit();
        if (glm::dot(normal, axis) >= std::cos(spread)) break;
        normal = axis;
      }
      const glm::dvec3 u = glm::normalize(glm::cross(normal, random_unit()));
      const glm::dvec3 v = glm::cross(normal, u);
      const glm::dvec3 at = centre + size * glm::dvec3(unit(random), unit(random), unit(random));
      for (const glm::dvec3& q : {at, at + size * u, at + size * v}) {
        scene.indices.push_back(std::uint32_t(scene.positions.size()));
        scene.positions.push_back(glm::vec3(q));
      }
    }
    const GpuRecord record{0, 16, 0, 0, 1, {}};
    const ClusterBounds bounds = cluster_bounds(scene, record);
    check_bounds(scene, record, bounds);
    for (int e = 0; e < 20; ++e) {
      const glm::dvec3 eye = centre + 60.0 * std::abs(unit(random)) * random_unit();
      ++random_eyes;
      if (!cluster_faces_away(bounds.centre - eye, bounds.radius, bounds.normal_axis,
                              bounds.normal_spread_sin))
        continue;
      ++claimed;
      ASSERT_TRUE(all_face_away(scene, record, eye)) << "cluster " << k << ", eye " << e;
    }
  }
  std::printf("random clusters: %zu of %zu views claimed facing away\n", claimed, random_eyes);
  EXPECT_GT(claimed, random_eyes / 10);

  const Scene city = build_city();
  const std::vector<GpuRecord> clusters = make_cluster_records(city);
  std::size_t city_claimed = 0, city_triangles = 0, city_claimed_triangles = 0;
  for (const GpuRecord& record : clusters) {
    const ClusterBounds bounds = cluster_bounds(city, record);
    check_bounds(city, record, bounds);
    for (const double t : {0.0, 12.0, 31.0}) {
      const glm::dvec3 eye(CityCameraPath(CityOptions{}).T_world_eye(t)[3]);
      city_triangles += record.triangle_count;
      if (!cluster_faces_away(bounds.centre - eye, bounds.radius, bounds.normal_axis,
                              bounds.normal_spread_sin))
        continue;
      ++city_claimed;
      city_claimed_triangles += record.triangle_count;
      ASSERT_TRUE(all_face_away(city, record, eye)) << "city cluster " << record.first_id;
    }
  }
  std::printf("city: %zu cluster views facing away, %zu of %zu triangle views\n", city_claimed,
              city_claimed_triangles, city_triangles);
  EXPECT_GT(5 * city_claimed_triangles, city_triangles);
}

TEST(Pipeline, GpuCoverageMatchesCpuReference) {
  test::shared_context();
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<std::array<glm::vec3, 3>> triangles;
  for (int k = 0; k < 400; ++k) {
    const float scale = std::pow(10.0f, unit(random) * 2.0f);  // 1 cm to 100 m
    const glm::vec3 centre(unit(random) * 5, unit(random) * 3, unit(random) * 5);
    std::array<glm::vec3, 3> t;
    for (auto& p : t) p = centre + scale * glm::vec3(unit(random), unit(random), unit(random));
    triangles.push_back(t);
  }
  triangles.push_back({glm::vec3(-1, -1, 0), glm::vec3(1, -1, 0), glm::vec3(0, 1, 0)});  // eye
  triangles.push_back({glm::vec3(-1e4f, -1, -1e4f), glm::vec3(1e4f, -1, -1e4f),
                       glm::vec3(0, -1, 1e4f)});  // huge ground
  // Across the cylinder's 360° seam (behind the eye, +z), through its vertical axis, around the
  // dome's pole (+y) and at it, small and large.
  for (float size : {0.01f, 0.3f, 3.0f}) {
    triangles.push_back(
        {glm::vec3(-size, -0.2f, 2), glm::vec3(size, -0.2f, 2), glm::vec3(0, size, 2)});
    triangles.push_back(
        {glm::vec3(0, -size, -size), glm::vec3(0, size, -size), glm::vec3(0, 0, size)});
    triangles.push_back(
        {glm::vec3(-size, 3, -size), glm::vec3(size, 3, -size), glm::vec3(0, 3, size)});
    triangles.push_back({glm::vec3(0, 3, 0), glm::vec3(size, 3, 0), glm::vec3(0, 3, size)});
  }
  // Dense facets: large triangles cover thousands of them (up to 26,060 here), far more than
  // llvmpipe's loop budget per shader invocation would allow one test each.
  RenderSettings dense;
  dense.facets.layout = FacetGrid{120, 120};
  // A tilted perspective base: the grid's gnomonic chart boxes (CoverageGrid::gnomonic_box).
  RenderSettings perspective_grid;
  perspective_grid.facets.layout = FacetGrid{16, 12};
  const std::vector<OutputSpec> perspective = {
      {"perspective",
       Warp::analytic(BaseProjection::perspective_fov(100, 70), {320, 240}, {2, 2},
                      glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.5, glm::dvec3(1, 0.3, 0.2))))}};
  for (const auto& [name, outputs, settings] :
       {std::tuple{"cylinder", cylinder(), strips(40)},
        std::tuple{"dome", dome(), RenderSettings{}},
        std::tuple{"dome, 28,800 facets", dome(), dense},
        std::tuple{"perspective 100x70 tilted", perspective, perspective_grid}}) {
    for (const auto& [coverage, cull] :
         {std::pair{FacetCoverage::grid, false}, std::pair{FacetCoverage::grid, true},
          std::pair{FacetCoverage::walk, true}}) {
      RenderSettings s = settings;
      s.cull_back_faces = cull;
      s.coverage = coverage;
      GpuCoverageRoutes routes;
      const auto gpu_lists = gpu_triangle_coverage(outputs[0].warp, s, triangles, &routes);
      std::printf(
          "%s, %s coverage%s: %u triangles to the grid pass, %u to the wide pass, %u "
          "walked\n",
          name, coverage == FacetCoverage::grid ? "grid" : "walk", cull ? ", culled" : "",
          routes.grid, routes.wide, routes.walk);
      // Every route is checked below: on the domes the large triangles go to the wide pass, and
      // those over thousands of the dense dome's facets on to the walk.
      const std::string_view display = name;
      if (display.starts_with("dome") && coverage == FacetCoverage::grid) {
        EXPECT_GT(routes.wide, 0u) << name;
        if (display.ends_with("28,800 facets")) {
          EXPECT_GT(routes.walk, 0u) << name;
        }
      }
      if (coverage == FacetCoverage::walk) {
        EXPECT_EQ(routes.grid + routes.wide + routes.walk, 0u) << name;
      }
      const FacetMesh mesh = build_facets(outputs[0].warp, s.facets);
      const CoverageIndex tight(mesh);
      const CoverageIndex loose(mesh, 0.25);  // bound on the GPU's rounding slack
      // Compared as pieces: the grid lists a cell's quad where the reference lists its two
      // facets, and the walk writes the quad once for each of them.
      const FacetPieces pieces = make_facet_pieces(mesh, s.merge_coplanar_facets);
      const auto as_pieces = [&](std::vector<std::uint32_t> ids) {
        for (auto& id : ids)
          if (id < pieces.facet_count) id = pieces.piece_of_facet[id];
        std::sort(ids.begin(), ids.end());
        ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
        return ids;
      };
      std::size_t cpu_pairs = 0, gpu_pairs = 0;
      for (std::size_t t = 0; t < triangles.size(); ++t) {
        std::array<glm::dvec3, 3> d;
        for (int c = 0; c < 3; ++c) d[c] = glm::dvec3(triangles[t][c]);
        std::vector<std::uint32_t> expected, bound;
        tight.query(d, expected, cull);
        loose.query(d, bound, cull);
        // A quad meets the triangle where its own guarded pyramid does; its facets' guarded
        // pyramids reach a little beyond it, at the ends of the diagonal.
        expected = as_pieces(expected);
        std::erase_if(expected, [&](std::uint32_t p) {
          return p >= pieces.facet_count && !triangle_meets_cone(d, pieces.planes[p].data(), 4);
        });
        bound = as_pieces(bound);
        const std::vector<std::uint32_t> gpu = as_pieces(gpu_lists[t]);
        const glm::dvec3 normal = glm::cross(d[1] - d[0], d[2] - d[0]);
        if (std::abs(glm::dot(normal, d[0])) <= 1e-6 * glm::length(normal) * glm::length(d[0])) {
          // Seen edge-on through the eye: it rasterizes to nothing, so pass 1 culls it, while the
          // reference lists the pyramids its plane passes through. The one difference, by design.
          EXPECT_TRUE(gpu.empty()) << name << " triangle " << t;
          continue;
        }
        cpu_pairs += expected.size();
        gpu_pairs += gpu.size();
        // Conservative: every piece the reference lists.
        EXPECT_TRUE(std::includes(gpu.begin(), gpu.end(), expected.begin(), expected.end()))
            << name << " triangle " << t << ": " << gpu.size() << " pieces listed, "
            << expected.size() << " in the reference";
        // Tight: nothing beyond the reference grown by 0.25 px of guard band, wherever the grid's
        // separating-plane test is exact: the triangle and the piece in the open hemisphere
        // about the triangle's mean direction (replication_lib.comp, may_meet). The walk is
        // tight everywhere.
        std::array<glm::dvec3, 3> u;
        for (int c = 0; c < 3; ++c) u[c] = glm::normalize(d[c]);
        const glm::dvec3 middle = glm::normalize(u[0] + u[1] + u[2]);
        const auto in_middle_hemisphere = [&](std::uint32_t p) {
          for (const glm::dvec3& v : u)
            if (!(glm::dot(middle, v) > 0)) return false;
          for (const glm::dvec3& c : pieces.corners[p])
            if (!(glm::dot(middle, c) > 0)) return false;
          return true;
        };
        for (const std::uint32_t p : gpu) {
          if (std::binary_search(bound.begin(), bound.end(), p)) continue;
          EXPECT_TRUE(coverage == FacetCoverage::grid && !in_middle_hemisphere(p))
              << name << " triangle " << t << ": piece " << p << " beyond the bound";
        }
      }
      EXPECT_GT(cpu_pairs, triangles.size());
      // Extra pairs from the float slack: at most 1% of the reference's.
      EXPECT_LE(gpu_pairs, cpu_pairs + cpu_pairs / 100) << name;
      std::printf("%s, %s coverage%s: %zu pairs, %.5f of the reference's\n", name,
                  coverage == FacetCoverage::grid ? "grid" : "walk", cull ? ", culled" : "",
                  gpu_pairs, double(gpu_pairs) / double(cpu_pairs));
    }
  }
}

TEST(Pipeline, ModernAndSeedPipelinesGiveIdenticalIds) {
  test::shared_context();
  const Scene scene = small_city();
  const auto outputs = cylinder();
  const glm::dmat4 view = city_view(3.0);
  const Rendered modern = render("facets", scene, outputs, strips(40), view);
  const Rendered seed = render("facets-gs", scene, outputs, strips(40), view);
  EXPECT_EQ(modern.stats.replicas, seed.stats.replicas);
  EXPECT_EQ(modern.stats.triangles_in, seed.stats.triangles_in);
  EXPECT_GT(modern.stats.replication_ratio(), 1.0);
  ASSERT_EQ(modern.ids[0].size(), seed.ids[0].size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < modern.ids[0].size(); ++k)
    differing += modern.ids[0][k] != seed.ids[0][k];
  EXPECT_EQ(differing, 0u);
  // The city fills the lower half of a street-level view and more.
  EXPECT_GT(modern.ids[0].size() - count_value(modern.ids[0], 0), modern.ids[0].size() / 2);
}

// The tessellator form draws what `facets` draws: the same IDs pixel for pixel and the same
// replica count, on strips, on 0.25 px tolerance layouts of the cylinder and the tilted dome (with
// quads and without), and with the levels capped at 1 so that every replica after a triangle's
// first comes from a further instance of the draw (as beyond 64² = 4096 replicas uncapped).
TEST(Pipeline, TessellatedFormGivesTheFacetsIds) {
  test::shared_context();
  const Scene scene = small_city();
  RenderSettings quarter_px;
  quarter_px.facets.layout = FacetTolerance{0.25};
  RenderSettings facets_only = quarter_px;
  facets_only.merge_coplanar_facets = false;
  RenderSettings capped = strips(40);
  capped.tessellated_max_level = 1;
  const glm::dmat4 tilted =
      glm::dmat4(glm::rotate(glm::dmat4(1.0), -1.2, glm::dvec3(1, 0, 0))) * city_view(2.0);
  for (const auto& [name, outputs, settings, view] :
       {std::tuple{"cylinder strips", cylinder(), strips(40), city_view(3.0)},
        std::tuple{"cylinder strips, levels 1", cylinder(), capped, city_view(3.0)},
        std::tuple{"cylinder 0.25 px", cylinder(), quarter_px, city_view(5.0)},
        std::tuple{"dome 0.25 px, facets", dome(), facets_only, tilted}}) {
    const Rendered modern = render("facets", scene, outputs, settings, view);
    const Rendered tess = render("tessellated", scene, outputs, settings, view);
    EXPECT_EQ(tess.stats.replicas, modern.stats.replicas) << name;
    EXPECT_EQ(tess.stats.triangles_visible, modern.stats.triangles_visible) << name;
    EXPECT_EQ(tess.stats.triangles_in, modern.stats.triangles_in) << name;
    ASSERT_EQ(tess.ids[0].size(), modern.ids[0].size());
    std::size_t differing = 0;
    for (std::size_t k = 0; k < modern.ids[0].size(); ++k)
      differing += modern.ids[0][k] != tess.ids[0][k];
    EXPECT_EQ(differing, 0u) << name;
    EXPECT_GT(modern.ids[0].size() - count_value(modern.ids[0], 0), modern.ids[0].size() / 4)
        << name;
    EXPECT_GT(modern.stats.replication_ratio(), 1.0) << name;
  }
}

// `facets` and `naive` on the cylinder's 40 strips from city_view(3.0), and how many ID pixels
// differ between them.
struct FacetsAndNaive {
  Rendered modern, naive;
  std::size_t differing = 0;
};
FacetsAndNaive render_facets_and_naive(const Scene& scene) {
  const auto outputs = cylinder();
  const glm::dmat4 view = city_view(3.0);
  FacetsAndNaive result{render("facets", scene, outputs, strips(40), view),
                        render("naive", scene, outputs, strips(40), view)};
  for (std::size_t k = 0; k < result.modern.ids[0].size(); ++k)
    result.differing += result.modern.ids[0][k] != result.naive.ids[0][k];
  return result;
}

TEST(Pipeline, NaiveMatchesFacetsExceptOnDepthTies) {
  test::shared_context();
  const FacetsAndNaive both = render_facets_and_naive(small_city());
  // Both draw the same (triangle, facet) fragments with the same arithmetic, in another order,
  // so only exact depth ties can resolve differently: at most 0.2% of pixels.
  EXPECT_LE(both.differing, both.modern.ids[0].size() / 500) << both.differing;
  EXPECT_GE(both.naive.stats.replicas, both.modern.stats.replicas);
}

// Clusters of mirrored and unevenly scaled objects: a mirror turns the winding normals, which the
// clusters' cones follow, and an uneven scale is not a similarity, so its clusters keep no cone.
// facets (clusters) and naive (whole objects) then draw the same image, as for the city itself.
TEST(Pipeline, ClusterCullingFollowsMirroredAndScaledObjects) {
  test::shared_context();
  Scene scene = small_city();
  std::size_t mirrored = 0, scaled = 0;
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    Object& object = scene.objects[o];
    const glm::vec3 c = 0.5f * (object.bounds_world.p_min + object.bounds_world.p_max);
    const glm::vec3 scale = o % 3 == 0   ? glm::vec3(-1, 1, 1)
                            : o % 3 == 1 ? glm::vec3(1, 1.7f, 0.6f)
                                         : glm::vec3(1);
    mirrored += o % 3 == 0;
    scaled += o % 3 == 1;
    object.T_world_object = glm::translate(glm::mat4(1.0f), c) *
                            glm::scale(glm::mat4(1.0f), scale) *
                            glm::translate(glm::mat4(1.0f), -c);
  }
  scene.update_bounds();
  ASSERT_GT(mirrored, 10u);
  ASSERT_GT(scaled, 10u);
  const FacetsAndNaive both = render_facets_and_naive(scene);
  const std::vector<std::uint32_t>& ids = both.modern.ids[0];
  EXPECT_LE(both.differing, ids.size() / 500) << both.differing;
  EXPECT_GT(ids.size() - count_value(ids, 0), ids.size() / 4);
  // Clusters facing away left the facets list.
  EXPECT_LT(both.modern.stats.triangles_in, both.naive.stats.triangles_in);
}

TEST(Pipeline, BackgroundSphereLeavesNoHoles) {
  test::shared_context();
  const Scene sphere = background_sphere(96, 48, 50.0f);
  // The 400×300 cylinder at 1 px is 28 columns of 14.3×300 px cells: thin facets whose long
  // diagonals run through pixel centres (one at (237.5, 187.5)). With the guard scaled about the
  // centroid those seams moved by 0.0014 px, under llvmpipe's subpixel snapping, and such pixel
  // centres were drawn by neither facet.
  RenderSettings one_px;
  one_px.facets.layout = FacetTolerance{1.0};
  for (const auto& [name, outputs, settings] :
       {std::tuple{"cylinder strips", cylinder(), strips(160)},
        std::tuple{"cylinder tolerance", cylinder(), RenderSettings{}},
        std::tuple{"cylinder thin cells",
                   load_display_outputs("builtin:cylinder360", glm::ivec2(400, 300)), one_px},
        std::tuple{"dome", dome(), RenderSettings{}}}) {
    for (std::string_view method : {"facets", "facets-gs", "naive"}) {
      const Rendered r = render(method, sphere, outputs, settings, glm::dmat4(1.0));
      const auto& ids = r.ids[0];
      std::size_t holes = count_value(ids, 0);
      if (std::string_view(name) == "dome") {
        // Pixels outside the fisheye circle (radius W/2 about the centre) see nothing.
        holes = 0;
        const int w = kDomeSize.x;
        for (int j = 0; j < kDomeSize.y; ++j)
          for (int i = 0; i < w; ++i) {
            const double dx = i + 0.5 - w / 2.0, dy = j + 0.5 - w / 2.0;
            if (std::hypot(dx, dy) < w / 2.0 - 1.0 && ids[std::size_t(j * w + i)] == 0) ++holes;
          }
      }
      EXPECT_EQ(holes, 0u) << name << " " << method;
    }
  }
}

// The grid must draw what the hierarchy walk draws: the same IDs on every base, with quads and
// without, and facet for facet at most 1% more replicas (clipped to nothing) from its candidate
// reject without clipping.
// An unlit material (glTF KHR_materials_unlit) shows its base colour exactly in every method:
// each covered pixel of an inward sphere around the eye is the colour's sRGB encoding within one
// step; the same material lit is shaded.
TEST(Pipeline, UnlitMaterialShowsItsBaseColour) {
  test::shared_context();
  Scene sphere = background_sphere(24, 12, 10.0f);
  const glm::vec4 base_colour(0.2f, 0.5f, 0.8f, 1.0f);
  sphere.materials[0].base_colour = base_colour;
  const auto encode = [](float linear) {
    const double s =
        linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(double(linear), 1 / 2.4) - 0.055;
    return int(std::lround(255 * s));
  };
  const int expected[3] = {encode(base_colour.x), encode(base_colour.y), encode(base_colour.z)};
  const auto outputs = load_display_outputs("builtin:cylinder360", glm::ivec2(64, 48));
  for (const bool unlit : {true, false}) {
    sphere.materials[0].unlit = unlit;
    const GpuScene gpu = upload_scene(sphere);
    for (std::string_view method : {"facets", "facets-gs", "naive", "cubemap", "vertex"}) {
      SCOPED_TRACE(std::string(method) + (unlit ? " unlit" : " lit"));
      auto renderer = make_render_method(method);
      renderer->prepare(sphere, gpu, outputs, RenderSettings{});
      std::vector<OutputTarget> targets;
      targets.push_back(OutputTarget::create(outputs[0].warp.output_size));
      renderer->render(glm::dmat4(1.0), targets);
      const std::vector<std::uint8_t> rgba = targets[0].read_colour_rgba8();
      const std::vector<std::uint32_t> ids = targets[0].read_ids();
      check_gl_error("render");
      int covered = 0, off = 0;
      for (std::size_t p = 0; p < ids.size(); ++p) {
        if (ids[p] == 0) continue;
        ++covered;
        bool exact = true;
        for (int c = 0; c < 3; ++c) exact = exact && std::abs(rgba[4 * p + c] - expected[c]) <= 1;
        off += !exact;
      }
      EXPECT_GT(covered, int(ids.size()) * 9 / 10);
      if (unlit)
        EXPECT_EQ(off, 0);
      else
        EXPECT_GT(off, covered / 2);
      if (!unlit) break;  // shading when lit is the same code in every method
    }
  }
}

TEST(Pipeline, GridCoverageGivesTheWalksIds) {
  test::shared_context();
  const Scene scene = small_city();
  RenderSettings quarter_px;
  quarter_px.facets.layout = FacetTolerance{0.25};
  Warp deformation =
      Warp::analytic(BaseProjection::perspective(-1, 1, 0.75, -0.75), {256, 192}, {21, 16});
  for (int j = 0; j < deformation.grid_size.y; ++j)
    for (int i = 0; i < deformation.grid_size.x; ++i) {
      const double s = double(i) / 20, t = double(j) / 15;
      deformation.offset_px[deformation.node_index(i, j)] =
          glm::vec2(float(8 * std::sin(6 * s) * std::cos(5 * t)), float(6 * std::sin(4 * t + s)));
    }
  RenderSettings grid_20x15;
  grid_20x15.facets.layout = FacetGrid{20, 15};
  const glm::dmat4 tilted =
      glm::dmat4(glm::rotate(glm::dmat4(1.0), -1.2, glm::dvec3(1, 0, 0))) * city_view(2.0);
  for (const auto& [name, outputs, settings, view] :
       {std::tuple{"cylinder 0.25 px", cylinder(), quarter_px, city_view(3.0)},
        std::tuple{"cylinder strips", cylinder(), strips(160), city_view(5.0)},
        std::tuple{"dome 0.25 px", dome(), quarter_px, tilted},
        std::tuple{"deformation", std::vector<OutputSpec>{{"deformation", deformation}}, grid_20x15,
                   city_view(4.0)}}) {
    std::vector<std::uint32_t> ids[2];
    std::uint64_t grid_replicas[2] = {0, 0};
    for (const bool merge : {true, false}) {
      RenderSettings by_grid = settings;
      by_grid.merge_coplanar_facets = merge;
      RenderSettings walk = by_grid;
      walk.coverage = FacetCoverage::walk;
      const Rendered grid = render("facets", scene, outputs, by_grid, view);
      const Rendered by_walk = render("facets", scene, outputs, walk, view);
      const Rendered seed = render("facets-gs", scene, outputs, by_grid, view);
      const char* pieces = merge ? "quads" : "facets";
      EXPECT_EQ(grid.ids[0], by_walk.ids[0]) << name << ", " << pieces;
      EXPECT_EQ(grid.ids[0], seed.ids[0]) << name << ", " << pieces;
      EXPECT_GT(by_walk.ids[0].size() - count_value(by_walk.ids[0], 0), by_walk.ids[0].size() / 4)
          << name;
      EXPECT_EQ(seed.stats.replicas, grid.stats.replicas) << name << ", " << pieces;
      EXPECT_EQ(by_walk.stats.triangles_sole_piece, 0u) << name;
      // Some of the city's objects lie inside one of the cylinder's quads: the shortcut is taken.
      if (merge && std::string_view(name) == "cylinder 0.25 px") {
        EXPECT_GT(grid.stats.triangles_sole_piece, 0u);
      }
      if (!merge) {
        EXPECT_GE(grid.stats.replicas, by_walk.stats.replicas) << name;
        EXPECT_LE(double(grid.stats.replicas), 1.01 * double(by_walk.stats.replicas)) << name;
      }
      ids[merge ? 0 : 1] = grid.ids[0];
      grid_replicas[merge ? 0 : 1] = grid.stats.replicas;
      std::printf(
          "%s, %s: grid %llu replicas, walk %llu (%.4f); %llu of %llu triangles in objects "
          "inside one piece\n",
          name, pieces, static_cast<unsigned long long>(grid.stats.replicas),
          static_cast<unsigned long long>(by_walk.stats.replicas),
          double(grid.stats.replicas) / double(by_walk.stats.replicas),
          static_cast<unsigned long long>(grid.stats.triangles_sole_piece),
          static_cast<unsigned long long>(grid.stats.triangles_in));
    }
    // Quads only take replicas away. Their images differ from the facets' only where clipping
    // along a cell's diagonal rounds a scene triangle's edge across a pixel centre.
    EXPECT_LE(grid_replicas[0], grid_replicas[1]) << name;
    std::size_t differing = 0;
    for (std::size_t k = 0; k < ids[0].size(); ++k) differing += ids[0][k] != ids[1][k];
    EXPECT_LE(differing, ids[0].size() / 5000) << name;
    std::printf("%s: quads against facets, %zu pixels differ\n", name, differing);
  }
}

// 340 small objects about the eye, 8 to 20 m away in every direction and a quarter of them about
// +z (the cylinder's seam): fans of 1 to 130 triangles facing the eye, 0.05 to 1.8 m in radius,
// in three materials, so that the list's entries start at many positions within its blocks of
// 64 triangles.
Scene many_small_objects() {
  Scene scene;
  scene.materials.resize(3);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (std::uint32_t o = 0; o < 340; ++o) {
    glm::dvec3 d;
    do d = {unit(random), unit(random), unit(random)};
    while (glm::length(d) < 0.1 || glm::length(d) > 1.0);
    // Every fourth about +z, the cylinder's seam: its cells wrap there.
    if (o % 4 == 0) d = glm::dvec3(0.05 * d.x, 0.3 * d.y, 1.0);
    double distance = 14.0 + 6.0 * unit(random);
    // The last 40 in a row across the seam at 0.001 rad steps, 0.015 rad in radius: some have
    // their centres in the first or last cell and reach into the guard band of the cell across
    // the seam.
    if (o >= 300) {
      const double azimuth = 0.001 * (double(o) - 320.0);
      d = glm::dvec3(std::sin(azimuth), 0.0, std::cos(azimuth));
      distance = 20.0;
    }
    d = glm::normalize(d);
    const glm::dvec3 centre = distance * d;
    const glm::dvec3 u = glm::normalize(
        glm::cross(d, std::abs(d.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
    const glm::dvec3 v = glm::cross(d, u);
    const std::uint32_t triangles = 1 + (o * 37) % 130;
    const double size = o >= 300 ? 0.3 : 0.2 + 0.4 * (o % 5);  // metres
    const std::uint32_t first_index = std::uint32_t(scene.indices.size());
    for (std::uint32_t k = 0; k < triangles; ++k) {
      const double a0 = 2 * M_PI * k / triangles, a1 = 2 * M_PI * (k + 1) / triangles;
      // Counter-clockwise seen from the eye: front faces.
      for (const glm::dvec3& p : {centre, centre + size * (std::cos(a1) * u + std::sin(a1) * v),
                                  centre + size * (std::cos(a0) * u + std::sin(a0) * v)}) {
        scene.indices.push_back(std::uint32_t(scene.positions.size()));
        scene.positions.push_back(glm::vec3(p));
        scene.normals.push_back(glm::vec3(-d));
        scene.uvs.push_back({0, 0});
      }
    }
    scene.primitives.push_back({first_index, 3 * triangles, o % 3});
    Object object;
    object.first_primitive = o;
    object.primitive_count = 1;
    scene.objects.push_back(object);
  }
  scene.update_bounds();
  return scene;
}

// Object culling and the triangle list built on the GPU (list_build.comp) draw what the CPU's
// list draws: the same IDs pixel for pixel, frame after frame of a moving view and with an object
// moved between frames, for `methods`, on the cases named in `cases` (all when empty) of: strips
// and tolerance layouts of the cylinder, a tilted dome and the 2 × 2 wall's four outputs, with
// the city and with 300 small objects. The GPU's culling keeps every object the CPU's keeps (it
// tests the nodes' pyramids, not their cones), and at most a tenth more triangles.
void expect_gpu_list_gives_the_cpu_lists_ids(const std::vector<std::string>& methods,
                                             const std::set<std::string>& cases) {
  test::shared_context();
  RenderSettings quarter_px;
  quarter_px.facets.layout = FacetTolerance{0.25};
  const glm::dmat4 tilt = glm::rotate(glm::dmat4(1.0), -1.2, glm::dvec3(1, 0, 0));
  const auto wall = load_display_outputs("builtin:wall2x2", glm::ivec2(128, 80));
  ASSERT_EQ(wall.size(), 4u);
  Scene city = small_city(), small_objects = many_small_objects();
  ASSERT_GT(city.objects.size(), 4u);
  for (const auto& [name, scene_ptr, outputs, settings, T_view] :
       {std::tuple{"cylinder strips", &city, cylinder(), strips(40), glm::dmat4(1.0)},
        std::tuple{"cylinder 0.25 px", &city, cylinder(), quarter_px, glm::dmat4(1.0)},
        std::tuple{"dome 0.25 px, tilted", &city, dome(), quarter_px, tilt},
        std::tuple{"wall2x2 0.25 px", &city, wall, quarter_px, glm::dmat4(1.0)},
        std::tuple{"small objects, cylinder", &small_objects,
                   load_display_outputs("builtin:cylinder360", glm::ivec2(400, 300)), quarter_px,
                   glm::dmat4(1.0)},
        std::tuple{"small objects, cylinder strips", &small_objects, cylinder(), strips(40),
                   glm::dmat4(1.0)},
        std::tuple{"small objects, dome", &small_objects, dome(), quarter_px, tilt}}) {
    if (!cases.empty() && !cases.contains(name)) continue;
    Scene& scene = *scene_ptr;
    const glm::mat4 T_rest = scene.objects[3].T_world_object;
    for (const std::string& method : methods) {
      SCOPED_TRACE(std::string(name) + ", " + method);
      const GpuScene gpu = upload_scene(scene);
      RenderSettings on_cpu = settings, on_gpu = settings;
      on_cpu.triangle_list = TriangleListBuild::cpu;
      on_gpu.triangle_list = TriangleListBuild::gpu;
      auto cpu_renderer = make_render_method(method);
      auto gpu_renderer = make_render_method(method);
      cpu_renderer->prepare(scene, gpu, outputs, on_cpu);
      gpu_renderer->prepare(scene, gpu, outputs, on_gpu);
      std::vector<OutputTarget> cpu_targets, gpu_targets;
      for (const auto& output : outputs) {
        cpu_targets.push_back(OutputTarget::create(output.warp.output_size));
        gpu_targets.push_back(OutputTarget::create(output.warp.output_size));
      }
      for (int frame = 0; frame < 3; ++frame) {
        // The third frame keeps the view and moves an object 20 m sideways.
        scene.objects[3].T_world_object =
            frame == 2 ? glm::translate(glm::mat4(1.0f), glm::vec3(20, 0, 0)) * T_rest : T_rest;
        scene.update_bounds();
        const double step = std::min(frame, 1);
        const glm::dmat4 view = &scene == &city ? T_view * city_view(1.0 + 2.0 * step)
                                                : T_view * glm::rotate(glm::dmat4(1.0), 0.4 * step,
                                                                       glm::dvec3(0, 1, 0));
        const RenderStats cpu_stats = cpu_renderer->render(view, cpu_targets);
        const RenderStats gpu_stats = gpu_renderer->render(view, gpu_targets);
        check_gl_error("render");
        EXPECT_FALSE(gpu_stats.reused_replication) << frame;
        EXPECT_TRUE(gpu_stats.triangle_list_on_gpu) << frame;
        EXPECT_FALSE(cpu_stats.triangle_list_on_gpu) << frame;
        EXPECT_GE(gpu_stats.triangles_in, cpu_stats.triangles_in) << frame;
        EXPECT_LE(gpu_stats.triangles_in, cpu_stats.triangles_in + cpu_stats.triangles_in / 10)
            << frame;
        EXPECT_GT(cpu_stats.triangles_in, 0u) << frame;
        // Sole pieces: never one the CPU would not give (float claims less), most of those.
        EXPECT_LE(gpu_stats.triangles_sole_piece, cpu_stats.triangles_sole_piece) << frame;
        EXPECT_GE(10 * gpu_stats.triangles_sole_piece, 9 * cpu_stats.triangles_sole_piece) << frame;
        std::size_t drawn = 0;
        for (std::size_t i = 0; i < outputs.size(); ++i) {
          const auto cpu_ids = cpu_targets[i].read_ids();
          const auto gpu_ids = gpu_targets[i].read_ids();
          ASSERT_EQ(cpu_ids.size(), gpu_ids.size());
          std::size_t differing = 0;
          for (std::size_t k = 0; k < cpu_ids.size(); ++k) differing += cpu_ids[k] != gpu_ids[k];
          EXPECT_EQ(differing, 0u) << "frame " << frame << ", output " << i;
          drawn += cpu_ids.size() - count_value(cpu_ids, 0);
        }
        EXPECT_GT(drawn, 500u) << frame;
        if (frame == 0)
          std::printf("%s, %s: list triangles GPU/CPU %llu/%llu, sole piece %llu/%llu\n", name,
                      method.c_str(), static_cast<unsigned long long>(gpu_stats.triangles_in),
                      static_cast<unsigned long long>(cpu_stats.triangles_in),
                      static_cast<unsigned long long>(gpu_stats.triangles_sole_piece),
                      static_cast<unsigned long long>(cpu_stats.triangles_sole_piece));
      }
      scene.objects[3].T_world_object = T_rest;
      scene.update_bounds();
    }
  }
}

TEST(Pipeline, GpuTriangleListGivesTheCpuListsIds) {
  expect_gpu_list_gives_the_cpu_lists_ids({"facets", "facets-gs"}, {});
}

// The tessellated pipeline takes the same triangle list as the other two; only its draw differs,
// so one case: the city on the cylinder's strips, its cheapest (2.7 s for the whole test, against
// 3.1 to 7.3 s with any one of the other six). llvmpipe's tessellator allocates per patch, and
// under the sanitizers' allocator the seven cases took most of the 15 minutes after which ctest
// stops a test; the tilted dome with the small objects alone took 515 s at load 4.
TEST(Pipeline, GpuTriangleListGivesTheCpuListsIdsTessellated) {
  expect_gpu_list_gives_the_cpu_lists_ids({"tessellated"}, {"cylinder strips"});
}

// The city's 4 × 4 tiles (545,008 triangles) on the cylinder at 0.25 px: thousands of objects,
// hundreds of them far behind the eye along the streets, within a degree of the cylinder's seam,
// where the cells wrap. The GPU's sole pieces are the CPU's but for a few small clusters that
// float's margin denies one, and it gives the same list and image.
TEST(Pipeline, GpuSolePiecesAreTheCpusOnTheCityTiles) {
  test::shared_context();
  const Scene scene = load_scene("builtin:city:4");
  const auto outputs = load_display_outputs("builtin:cylinder360", glm::ivec2(400, 300));
  const glm::dmat4 view = glm::inverse(CityCameraPath(CityOptions{}).T_world_eye(0.0));
  const GpuScene gpu = upload_scene(scene);
  std::vector<std::vector<std::uint32_t>> ids;
  std::vector<RenderStats> stats;
  for (const TriangleListBuild list : {TriangleListBuild::cpu, TriangleListBuild::gpu}) {
    RenderSettings settings;
    settings.facets.layout = FacetTolerance{0.25};
    settings.triangle_list = list;
    auto renderer = make_render_method("facets");
    renderer->prepare(scene, gpu, outputs, settings);
    std::vector<OutputTarget> targets;
    targets.push_back(OutputTarget::create(outputs[0].warp.output_size));
    stats.push_back(renderer->render(view, targets));
    ids.push_back(targets[0].read_ids());
  }
  EXPECT_GT(stats[0].triangles_sole_piece, stats[0].triangles_in / 3);
  // Float's margin (1e-6 of the distance) may deny a small cluster the piece double gives it,
  // never the reverse.
  EXPECT_LE(stats[1].triangles_sole_piece, stats[0].triangles_sole_piece);
  EXPECT_GE(1000 * stats[1].triangles_sole_piece, 999 * stats[0].triangles_sole_piece);
  std::printf("city:4 on the cylinder: sole piece GPU/CPU %llu/%llu of %llu list triangles\n",
              static_cast<unsigned long long>(stats[1].triangles_sole_piece),
              static_cast<unsigned long long>(stats[0].triangles_sole_piece),
              static_cast<unsigned long long>(stats[0].triangles_in));
  EXPECT_EQ(stats[1].triangles_in, stats[0].triangles_in);
  EXPECT_EQ(stats[1].replicas, stats[0].replicas);
  EXPECT_EQ(ids[1], ids[0]);
}

// A list of more triangles than one row of 65535 work groups of 64 holds (4,194,240, GL's least
// limit a dimension) is covered whole, with the list built on the CPU and on the GPU: the
// dispatches after the list come in rows (llvmpipe does not check an indirect dispatch's size,
// so there one row passes too). One triangle in the middle of a strip, then 4.3 million copies of
// a smaller one beside it.
TEST(Pipeline, ListsOfMoreThanOneDispatchRowAreCoveredWhole) {
  test::shared_context();
  Scene scene;
  scene.materials.resize(1);
  const glm::mat3 R_eye_strip(glm::rotate(glm::mat4(1.0f), -0.3927f, glm::vec3(0, 1, 0)));
  for (const glm::vec3& p :
       {glm::vec3(-0.15f, -0.25f, -1), glm::vec3(0.15f, -0.25f, -1), glm::vec3(0.0f, 0.05f, -1),
        glm::vec3(-0.04f, 0.2f, -1), glm::vec3(0.04f, 0.2f, -1), glm::vec3(0.0f, 0.28f, -1)}) {
    scene.positions.push_back(R_eye_strip * p);
    scene.normals.push_back({0, 0, 1});
    scene.uvs.push_back({0, 0});
  }
  const std::uint32_t triangles = 4'300'000;
  scene.indices.resize(3 * std::size_t(triangles));
  for (std::size_t i = 0; i < scene.indices.size(); ++i)
    scene.indices[i] = std::uint32_t(i % 3 + (i < 3 ? 0 : 3));
  scene.primitives.push_back({0, std::uint32_t(scene.indices.size()), 0});
  Object object;
  object.primitive_count = 1;
  scene.objects.push_back(object);
  scene.update_bounds();
  const auto outputs = load_display_outputs("builtin:cylinder360", glm::ivec2(128, 96));
  const GpuScene gpu = upload_scene(scene);
  for (const TriangleListBuild list : {TriangleListBuild::cpu, TriangleListBuild::gpu}) {
    SCOPED_TRACE(list == TriangleListBuild::gpu ? "GPU list" : "CPU list");
    RenderSettings settings = strips(8);
    settings.triangle_list = list;
    auto renderer = make_render_method("facets");
    renderer->prepare(scene, gpu, outputs, settings);
    std::vector<OutputTarget> targets;
    targets.push_back(OutputTarget::create(outputs[0].warp.output_size));
    const RenderStats stats = renderer->render(glm::dmat4(1.0), targets);
    check_gl_error("render");
    EXPECT_EQ(stats.triangles_in, triangles);
    EXPECT_EQ(stats.triangles_visible, triangles);
    EXPECT_EQ(stats.replicas, triangles);
    // The first triangle (ID 1), and the first copy (ID 2) in front of the later copies at the
    // same depth.
    const auto ids = targets[0].read_ids();
    EXPECT_GT(count_value(ids, 1), 10u);
    EXPECT_GT(count_value(ids, 2), 0u);
    EXPECT_EQ(count_value(ids, 0) + count_value(ids, 1) + count_value(ids, 2), ids.size());
  }
}

// The pair buffers start at one pair per triangle: a view that needs more overflows them, the
// frame is replicated again with room, and its image is the one a roomy frame gives. Both pair
// pipelines size their buffers this way, without reading the pair count back before drawing,
// with the triangle list built on the CPU or on the GPU.
TEST(Pipeline, AnOverflowingPairBufferRerunsToTheSameImage) {
  test::shared_context();
  const Scene scene = background_sphere(96, 48, 50.0f);  // 9,216 triangles, all in view
  const auto outputs = cylinder();
  const GpuScene gpu = upload_scene(scene);
  const glm::dmat4 view_a(1.0);
  const glm::dmat4 view_b = glm::dmat4(glm::rotate(glm::dmat4(1.0), 0.3, glm::dvec3(0, 1, 0)));
  std::vector<std::uint32_t> ids_of_facets;
  for (const auto& [method, list] :
       {std::pair{"facets", TriangleListBuild::cpu}, std::pair{"facets-gs", TriangleListBuild::cpu},
        std::pair{"facets", TriangleListBuild::gpu},
        std::pair{"facets-gs", TriangleListBuild::gpu}}) {
    SCOPED_TRACE(std::string(method) + (list == TriangleListBuild::gpu ? ", GPU list" : ""));
    auto renderer = make_render_method(method);
    RenderSettings settings = strips(160);
    settings.triangle_list = list;
    renderer->prepare(scene, gpu, outputs, settings);
    std::vector<OutputTarget> targets;
    targets.push_back(OutputTarget::create(kCylinderSize));
    const RenderStats first = renderer->render(view_a, targets);
    const auto ids_first = targets[0].read_ids();
    EXPECT_EQ(first.overflow_reruns, 1u);
    EXPECT_GT(first.replicas, scene.triangle_count());
    renderer->render(view_b, targets);
    const RenderStats roomy = renderer->render(view_a, targets);
    EXPECT_EQ(roomy.overflow_reruns, 0u);
    EXPECT_EQ(roomy.replicas, first.replicas);
    EXPECT_EQ(targets[0].read_ids(), ids_first);
    EXPECT_EQ(count_value(ids_first, 0), 0u);
    if (ids_of_facets.empty())
      ids_of_facets = ids_first;
    else
      EXPECT_EQ(ids_first, ids_of_facets);
  }
}

TEST(Pipeline, ReplicationIsReusedWhileTheViewStands) {
  test::shared_context();
  const Scene scene = small_city();
  const auto outputs = cylinder();
  const GpuScene gpu = upload_scene(scene);
  auto renderer = make_render_method("facets");
  renderer->prepare(scene, gpu, outputs, strips(40));
  std::vector<OutputTarget> targets;
  targets.push_back(OutputTarget::create(kCylinderSize));
  const RenderStats first = renderer->render(city_view(1.0), targets);
  const auto ids_first = targets[0].read_ids();
  const RenderStats again = renderer->render(city_view(1.0), targets);
  EXPECT_FALSE(first.reused_replication);
  EXPECT_TRUE(again.reused_replication);
  EXPECT_EQ(again.replicas, first.replicas);
  EXPECT_EQ(targets[0].read_ids(), ids_first);
  const RenderStats moved = renderer->render(city_view(2.0), targets);
  EXPECT_FALSE(moved.reused_replication);
}

// Triangles through the eye, behind it, huge and degenerate: no crash, no GL error, and only
// IDs of the scene's triangles.
TEST(Pipeline, HostileTrianglesAreStable) {
  test::shared_context();
  Scene scene;
  scene.materials.push_back({});
  const std::vector<glm::vec3> corners = {
      {-1, -1, 0},      {1, -1, 0},      {0, 1, 0},       // through the eye
      {-1, -1, 5},      {1, -1, 5},      {0, 1, 5},       // behind (for the cylinder: just visible)
      {-1e6, -2, -1e6}, {1e6, -2, -1e6}, {0, -2, 1e6},    // huge ground
      {0, 0, -3},       {0, 0, -3},      {0, 0, -3},      // degenerate
      {-1, 0, -1e-4f},  {1, 0, -1e-4f},  {0, 1, -1e-4f},  // nearer than z_near
  };
  for (std::uint32_t k = 0; k < corners.size(); ++k) {
    scene.positions.push_back(corners[k]);
    scene.normals.push_back({0, 1, 0});
    scene.uvs.push_back({0, 0});
    scene.indices.push_back(k);
  }
  scene.primitives.push_back({0, std::uint32_t(scene.indices.size()), 0});
  Object object;
  object.primitive_count = 1;
  scene.objects.push_back(object);
  scene.update_bounds();
  for (const auto& outputs : {cylinder(), dome()}) {
    for (std::string_view method : {"facets", "facets-gs", "naive"}) {
      RenderSettings settings;
      settings.cull_back_faces = false;
      const Rendered r = render(method, scene, outputs, settings, glm::dmat4(1.0));
      const std::string where = std::string(method) + " on " + outputs[0].name;
      for (std::uint32_t id : r.ids[0]) ASSERT_LE(id, 5u) << where;
      // The huge ground (ID 3) fills the lower half of the cylinder at least partly.
      EXPECT_GT(count_value(r.ids[0], 3), 0u) << where;
    }
  }
}

}  // namespace
}  // namespace facet::driver
