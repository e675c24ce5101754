#pragma once
// Which facets an eye-frame triangle may cover: the CPU reference of pass 1 (DESIGN.md).
//
// A triangle covers facet f when it meets f's guarded pyramid (the cone of the three clip planes
// of FacetMesh::clip_planes). The query clips the triangle against each candidate pyramid, so it
// is exact up to rounding, and conservative by the guard band. Candidates come from a bounding
// volume hierarchy of cones over the facets, so wrap-around at ±180°, triangles through the eye or
// the cylinder axis, and triangles partly behind the eye need no special cases.
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <optional>
#include <vector>

#include "facet/projection/facets.hpp"

namespace facet {

class CoverageIndex {
 public:
  struct Node {
    glm::dvec3 axis{0.0};  // unit axis of a cone holding every guarded facet pyramid below
    double sin_half_angle =
        1;  // half-angle of that cone; >= 1 means no bound (a half-space or more)
    double cos_half_angle = 0;
    std::uint32_t first =
        0;  // leaf: facets order[first, first+count); inner: children first, first+1
    std::uint32_t count = 0;  // 0 for an inner node
  };

  explicit CoverageIndex(const FacetMesh& mesh, double guard_px = kDefaultGuardPx);

  // Appends to `facets` (sorted, unique) every facet the triangle may cover. Throws InputError
  // when a vertex is not finite. A back-facing triangle (counter-clockwise seen from the eye is
  // front) is skipped when cull_back_faces is set.
  void query(const std::array<glm::dvec3, 3>& triangle, std::vector<std::uint32_t>& facets,
             bool cull_back_faces = false) const;

  // The facet whose (unguarded) pyramid contains direction v, nullopt when none does.
  std::optional<std::uint32_t> locate(glm::dvec3 v) const;

  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<std::uint32_t>& order() const { return order_; }
  const std::vector<std::array<glm::dvec3, 3>>& planes() const { return planes_; }

 private:
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<std::array<glm::dvec3, 3>> planes_;  // guarded clip planes per facet
  std::vector<std::array<glm::dvec3, 3>> edges_;   // unguarded edge normals per facet
};

// True when the triangle meets the convex cone {X : plane[k]·X >= 0 for all k}. Exact clipping in
// double precision.
bool triangle_meets_cone(const std::array<glm::dvec3, 3>& triangle, const glm::dvec3* planes,
                         int plane_count);

}  // namespace facet
