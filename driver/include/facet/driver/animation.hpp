#pragma once
// Moving objects: an object's pose for one frame (ObjectPose, carried by FrameState), and the
// keyframed node animations of a glTF scene (SceneAnimation), which give those poses over time.
//
// Frames and units as in scene.hpp: world and object frames in metres, y up; time in seconds.
#include <cstdint>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

namespace facet::driver {

// Where one scene object is this frame. Objects are identified by their index in
// Scene::objects (the order of the triangle-ID numbering, render_method.hpp), which the glTF
// loader and the API keep stable for a scene's life.
struct ObjectPose {
  std::uint32_t object = 0;        // index into Scene::objects
  glm::dmat4 T_world_object{1.0};  // object-frame points into the world frame (metres); affine

  bool operator==(const ObjectPose&) const = default;
};

enum class AnimationPath { translation, rotation, scale };
// glTF's interpolations: step holds a key's value until the next key; linear interpolates
// translation and scale linearly and rotation by spherical linear interpolation (the shorter
// way round); cubic_spline is glTF's Hermite spline with in- and out-tangents per key.
enum class AnimationInterpolation { step, linear, cubic_spline };

// One animated property of one glTF node.
struct AnimationChannel {
  std::uint32_t node = 0;  // glTF node index (AnimationNode::gltf_node)
  AnimationPath path = AnimationPath::translation;
  AnimationInterpolation interpolation = AnimationInterpolation::linear;
  std::vector<float> times_s;  // key times, strictly increasing, >= 0
  // Per key: 3 numbers (translation in metres, scale factors) or 4 (rotation quaternion x, y, z,
  // w); cubic_spline keys hold in-tangent, value, out-tangent in that order.
  std::vector<float> values;
};

// One glTF animation. Each clip loops on its own: at time t it shows t modulo duration_s.
struct AnimationClip {
  std::string name;
  double duration_s = 0;  // the last key time of its channels
  std::vector<AnimationChannel> channels;
};

// One visit of a node in the scene graph, parents before children. The rest pose is the node's
// translation, rotation and scale (T * R * S); a node given by a matrix keeps it and ignores
// channels.
struct AnimationNode {
  std::uint32_t gltf_node = 0;
  std::int32_t parent = -1;  // an earlier entry of SceneAnimation::nodes, or -1 for a root
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // (w, x, y, z), unit
  glm::dvec3 scale{1.0};
  bool has_matrix = false;
  glm::dmat4 matrix{1.0};  // T_parent_node when has_matrix
};

// A scene's node animations. Empty (no clips) for scenes that do not move by themselves.
struct SceneAnimation {
  std::vector<AnimationNode> nodes;
  // Per Scene::objects entry: the node entry that places it, or -1 (not under any node).
  std::vector<std::int32_t> object_node;
  std::vector<AnimationClip> clips;

  bool empty() const { return clips.empty(); }
  // The longest clip's duration (0 without clips).
  double duration_s() const;
};

// The poses at `time_s` of the objects the animation moves (those below a node that a channel
// targets), in object order; none for an empty animation. Each clip loops (a negative time
// counts back from the end); before a channel's first key it holds the first key's value.
std::vector<ObjectPose> animated_object_poses(const SceneAnimation& animation, double time_s);

}  // namespace facet::driver
