#include "facet/driver/animation.hpp"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace facet::driver {

namespace {

// A node's local transform parts at one time.
struct Trs {
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 scale{1.0};
};

// The channel's value at `t` (clip-local seconds), written into `trs`.
void sample(const AnimationChannel& channel, double t, Trs& trs) {
  const std::size_t keys = channel.times_s.size();
  if (keys == 0) return;
  const std::size_t components = channel.path == AnimationPath::rotation ? 4 : 3;
  const bool cubic = channel.interpolation == AnimationInterpolation::cubic_spline;
  // Key k's value (cubic: the middle of its three elements), tangent sets (in: 0, out: 2).
  const auto element = [&](std::size_t k, std::size_t which) {
    const std::size_t at = (cubic ? 3 * k + which : k) * components;
    glm::dvec4 v(0.0);
    for (std::size_t c = 0; c < components; ++c) v[int(c)] = channel.values[at + c];
    return v;
  };
  const auto value = [&](std::size_t k) { return element(k, 1); };
  glm::dvec4 result;
  const auto after = std::upper_bound(channel.times_s.begin(), channel.times_s.end(), float(t));
  if (after == channel.times_s.begin()) {
    result = value(0);
  } else if (after == channel.times_s.end()) {
    result = value(keys - 1);
  } else {
    const std::size_t k = std::size_t(after - channel.times_s.begin()) - 1;
    const double t0 = channel.times_s[k], t1 = channel.times_s[k + 1];
    const double dt = t1 - t0;
    const double u = std::clamp((t - t0) / dt, 0.0, 1.0);
    switch (channel.interpolation) {
      case AnimationInterpolation::step:
        result = value(k);
        break;
      case AnimationInterpolation::linear:
        if (channel.path == AnimationPath::rotation) {
          const glm::dvec4 a = value(k), b = value(k + 1);
          const glm::dquat q =
              glm::slerp(glm::dquat(a.w, a.x, a.y, a.z), glm::dquat(b.w, b.x, b.y, b.z), u);
          result = glm::dvec4(q.x, q.y, q.z, q.w);
        } else {
          result = glm::mix(value(k), value(k + 1), u);
        }
        break;
      case AnimationInterpolation::cubic_spline: {
        const double u2 = u * u, u3 = u2 * u;
        result = (2 * u3 - 3 * u2 + 1) * value(k) + (u3 - 2 * u2 + u) * dt * element(k, 2) +
                 (-2 * u3 + 3 * u2) * value(k + 1) + (u3 - u2) * dt * element(k + 1, 0);
        break;
      }
    }
  }
  switch (channel.path) {
    case AnimationPath::translation:
      trs.translation = glm::dvec3(result);
      break;
    case AnimationPath::scale:
      trs.scale = glm::dvec3(result);
      break;
    case AnimationPath::rotation: {
      const glm::dquat q(result.w, result.x, result.y, result.z);
      const double length = glm::length(q);
      if (length > 0) trs.rotation = q / length;
      break;
    }
  }
}

glm::dmat4 compose(const Trs& trs) {
  glm::dmat4 T(1.0);
  T[3] = glm::dvec4(trs.translation, 1.0);
  glm::dmat4 S(1.0);
  S[0][0] = trs.scale.x;
  S[1][1] = trs.scale.y;
  S[2][2] = trs.scale.z;
  return T * glm::mat4_cast(trs.rotation) * S;
}

}  // namespace

double SceneAnimation::duration_s() const {
  double longest = 0;
  for (const AnimationClip& clip : clips) longest = std::max(longest, clip.duration_s);
  return longest;
}

std::vector<ObjectPose> animated_object_poses(const SceneAnimation& animation, double time_s) {
  std::vector<ObjectPose> poses;
  if (animation.empty()) return poses;
  // Each glTF node's parts at this time: rest values, then every channel on it.
  std::uint32_t node_count = 0;
  for (const AnimationNode& node : animation.nodes)
    node_count = std::max(node_count, node.gltf_node + 1);
  std::vector<Trs> parts(node_count);
  std::vector<bool> targeted(node_count, false);
  for (const AnimationNode& node : animation.nodes)
    parts[node.gltf_node] = {node.translation, node.rotation, node.scale};
  for (const AnimationClip& clip : animation.clips) {
    double t = 0;
    if (clip.duration_s > 0) {
      t = std::fmod(time_s, clip.duration_s);
      if (t < 0) t += clip.duration_s;
    }
    for (const AnimationChannel& channel : clip.channels) {
      if (channel.node >= node_count) continue;
      sample(channel, t, parts[channel.node]);
      targeted[channel.node] = true;
    }
  }
  std::vector<glm::dmat4> T_world_node(animation.nodes.size());
  std::vector<bool> moves(animation.nodes.size(), false);
  for (std::size_t e = 0; e < animation.nodes.size(); ++e) {
    const AnimationNode& node = animation.nodes[e];
    const glm::dmat4 local = node.has_matrix ? node.matrix : compose(parts[node.gltf_node]);
    const bool has_parent = node.parent >= 0 && std::size_t(node.parent) < e;
    T_world_node[e] = has_parent ? T_world_node[std::size_t(node.parent)] * local : local;
    moves[e] = (!node.has_matrix && targeted[node.gltf_node]) ||
               (has_parent && moves[std::size_t(node.parent)]);
  }
  for (std::size_t o = 0; o < animation.object_node.size(); ++o) {
    const std::int32_t e = animation.object_node[o];
    if (e < 0 || std::size_t(e) >= animation.nodes.size() || !moves[std::size_t(e)]) continue;
    poses.push_back({std::uint32_t(o), T_world_node[std::size_t(e)]});
  }
  return poses;
}

}  // namespace facet::driver
