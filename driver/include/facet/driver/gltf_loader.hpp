#pragma once
// glTF 2.0 scenes (through tinygltf) into the plain CPU Scene.
#include <filesystem>

#include "facet/driver/scene.hpp"

namespace facet::driver {

// Loads a .gltf (JSON with embedded base64 or external buffers and images) or .glb file.
//
// - Units and frames as glTF: metres, y up. Each node with a mesh becomes one Object whose
//   T_world_object is the product of the node transforms from the root; vertex data stays in the
//   mesh's frame and is shared between nodes that instance the same mesh.
// - The default scene is loaded (the first one when none is marked; every root node when the
//   file has no scenes).
// - External buffers and images are read only from the glTF file's folder or below it, as
//   regular files, with URIs taken as written (no `~` or `$VAR` expansion): a URI leading out of
//   the folder (by "..", an absolute path or a link) or naming a FIFO is an InputError naming it.
// - Triangles, triangle strips and fans are loaded (strips and fans become lists); points and
//   lines are skipped. Missing normals are computed (area-weighted); missing texture
//   coordinates are 0.
// - Materials: pbrMetallicRoughness base colour factor and base colour texture (converted to
//   RGBA8); KHR_materials_unlit marks a material unlit (Material::unlit). A material's
//   `extras.facet_shader` gives its own shading (Material::shader): a built-in material's name
//   ("pen-and-ink") or a GLSL file (*.frag, relative to the glTF file's folder) defining
//   shade() against shaders/scene/material_interface.frag. Primitives without a material get a
//   default white one.
// - Cameras: every node of the scene with a camera (perspective or orthographic) becomes a
//   SceneCamera with the node's world transform, scale removed; the camera's own projection is
//   not used: the display decides what is seen.
// - Animations: translation, rotation and scale channels (STEP, LINEAR, CUBICSPLINE) go into
//   Scene::animation with the node graph they move; all clips play at once, each looping over
//   its own length. Objects keep their rest pose in T_world_object. Morph target weights are
//   skipped; nodes given by a matrix do not move.
//
// Throws facet::InputError naming the file (and the glTF field, where known) for unreadable,
// malformed or unsupported input: bad JSON, out-of-range indices or accessors, missing POSITION,
// sparse accessors, cyclic node graphs.
Scene load_gltf(const std::filesystem::path& path);

}  // namespace facet::driver
