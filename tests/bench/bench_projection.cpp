// Benchmarks of the projection core: facet building, error evaluation and coverage queries.
#include <benchmark/benchmark.h>

#include <random>

#include "facet/projection/coverage.hpp"
#include "facet/projection/facet_error.hpp"
#include "facet/projection/facets.hpp"

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

}  // namespace

BENCHMARK_MAIN();
