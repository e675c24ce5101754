#pragma once
// --eye, --look-at and --camera of `facet render` and `facet run`: the view of the scene
// (driver/scene_view.hpp holds the logic and its tests).
#include <CLI/CLI.hpp>
#include <iostream>
#include <string>

#include "facet/driver/scene_view.hpp"
#include "option_flags.hpp"

namespace facet::cli {

struct ViewFlags {
  std::string eye, look_at, camera;

  void add_to(CLI::App& command) {
    command.add_option("--eye", eye,
                       "Eye position X,Y,Z (metres, scene frame, y up); default for glTF: the "
                       "bounds' centre, or outside and above the model when that is inside it");
    command.add_option("--look-at", look_at,
                       "Point X,Y,Z the eye looks at (needs --eye; default: the bounds' centre)");
    command.add_option("--camera", camera, "Start at the scene file's camera of this name");
  }

  // The library options of the scene and its view and the flags that set them, for the
  // OptionFlags table of every command that renders a scene (render, run, bench, depth-image):
  // the three above, and --scene and --material, which each command declares with its own help.
  // "step" is the scene name's step (builtin:city:STEP), set by --scene. A command keeps the rows
  // of the flags it declares (keep_declared_flags): bench has no --material, depth-image only
  // --scene and --eye.
  static const OptionFlagList& option_flags() {
    static const OptionFlagList flags{{"material", "--material"}, {"scene", "--scene"},
                                      {"step", "--scene"},        {"camera", "--camera"},
                                      {"eye_world", "--eye"},     {"look_at_world", "--look-at"}};
    return flags;
  }

  driver::ViewRequest request() const {
    driver::ViewRequest request;
    if (!eye.empty()) request.eye_world = driver::parse_point(eye, "--eye");
    if (!look_at.empty()) request.look_at_world = driver::parse_point(look_at, "--look-at");
    request.camera = camera;
    return request;
  }
};

// choose_scene_view, with its message (where the default eye went, or an eye inside geometry)
// on stderr as "facet <command>: <message>".
inline driver::SceneView choose_view(const driver::Scene& scene, const driver::ViewRequest& request,
                                     bool builtin_city, const std::string& command) {
  driver::SceneView view = driver::choose_scene_view(scene, request, builtin_city);
  if (!view.message.empty()) std::cerr << "facet " << command << ": " << view.message << "\n";
  return view;
}

}  // namespace facet::cli
