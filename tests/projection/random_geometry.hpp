#pragma once
// Random directions and log-uniform sizes shared by the coverage tests.
#include <cmath>
#include <glm/glm.hpp>
#include <random>

namespace facet::test {

inline glm::dvec3 random_unit(std::mt19937_64& random) {
  std::normal_distribution<double> normal;
  glm::dvec3 v;
  do v = {normal(random), normal(random), normal(random)};
  while (glm::length(v) < 1e-6);
  return glm::normalize(v);
}

inline double log_uniform(std::mt19937_64& random, double lo, double hi) {
  return std::exp(std::uniform_real_distribution<double>(std::log(lo), std::log(hi))(random));
}

}  // namespace facet::test
