// Benchmarks of the projection core: facet building, error evaluation and coverage queries.
#include <benchmark/benchmark.h>

#include <random>
#include <string>

#include "facet/projection/coverage.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/facets.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace {

facet::Warp cylinder() {
  return facet::Warp::analytic(facet::BaseProjection::cylindrical(-180, 180, 1, -1), {1600, 1200});
}
facet::Warp dome() {
  return facet::Warp::analytic(facet::BaseProjection::fisheye(180), {2048, 2048});
}

void BM_BuildCylinderTolerance(benchmark::State& state) {
  const auto warp = cylinder();
  const double tolerance = double(state.range(0)) / 100.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(facet::build_facets(warp, {facet::FacetTolerance{tolerance}}));
  }
}
BENCHMARK(BM_BuildCylinderTolerance)->Arg(100)->Arg(25)->Unit(benchmark::kMillisecond);

void BM_BuildDomeTolerance(benchmark::State& state) {
  const auto warp = dome();
  const double tolerance = double(state.range(0)) / 100.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(facet::build_facets(warp, {facet::FacetTolerance{tolerance}}));
  }
}
BENCHMARK(BM_BuildDomeTolerance)->Arg(100)->Arg(25)->Unit(benchmark::kMillisecond);

void BM_CoverageQuery(benchmark::State& state) {
  const auto warp = cylinder();
  const auto mesh = facet::build_facets(warp, {facet::FacetStrips{int(state.range(0))}});
  const facet::CoverageIndex index(mesh);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<std::array<glm::dvec3, 3>> triangles(4096);
  for (auto& t : triangles) {
    const glm::dvec3 centre(20 * unit(random), 5 * unit(random), 20 * unit(random));
    for (auto& p : t) p = centre + glm::dvec3(unit(random), unit(random), unit(random));
  }
  std::vector<std::uint32_t> out;
  std::size_t k = 0;
  for (auto _ : state) {
    out.clear();
    index.query(triangles[k++ % triangles.size()], out);
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK(BM_CoverageQuery)->Arg(160)->Arg(640);

// facet play's preparation before its first frame: the warp inverse of one of dome4's four
// 1024×768 projectors at every pixel centre, as ContentPass builds its direction lookup.
facet::Warp dome4_projector() {
  return facet::read_warp(std::string(FACET_SOURCE_DIR) + "/configs/displays/dome4/p0.warp.exr");
}

void BM_WarpInverseBuild(benchmark::State& state) {
  const auto warp = dome4_projector();
  for (auto _ : state) benchmark::DoNotOptimize(facet::WarpInverse(warp));
}
BENCHMARK(BM_WarpInverseBuild)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_WarpInversePixelCentres(benchmark::State& state) {
  const facet::WarpInverse inverse(dome4_projector());
  for (auto _ : state) benchmark::DoNotOptimize(inverse.st_at_pixel_centres());
}
BENCHMARK(BM_WarpInversePixelCentres)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
