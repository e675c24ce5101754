// facet depth-image: renders a scene into a depth image (colour, distance, normals; planar or a
// DPCI) for `facet render --scene depth:FILE.exr` (driver/depth_image.hpp).
#include <cstdio>

#include "command.hpp"
#include "display_flags.hpp"
#include "facet/driver/depth_image.hpp"
#include "facet/driver/scene_names.hpp"
#include "facet/driver/scene_view.hpp"
#include "option_flags.hpp"
#include "view_flags.hpp"

namespace facet::cli {
namespace {

struct DepthImageFlags {
  std::string scene = "builtin:city", out, kind = "dpci", size, eye;
};

// The library options this command's flags set, for errors that name them (option_flags.hpp).
const OptionFlags option_flags{"depth-image",
                               {{"kind", "--kind"}, {"size", "--size"}, {"out", "--out"}},
                               ViewFlags::option_flags()};

const Registration registration{
    32, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "depth-image", "Render a scene into a depth image (RGB, Z, normals) for depth:FILE.exr");
      auto flags = std::make_shared<DepthImageFlags>();
      command->add_option("--scene", flags->scene, driver::kSceneNameSyntax)->capture_default_str();
      command->add_option("--out", flags->out, "FILE.exr to write")->required();
      command
          ->add_option("--kind", flags->kind,
                       "planar (90° wide perspective) | dpci (360° cylinder and top cap)")
          ->capture_default_str();
      command->add_option("--size", flags->size,
                          "WxH: the planar image, or the DPCI's cylinder (its cap is HxH); "
                          "default 512x512");
      command->add_option("--eye", flags->eye,
                          "Eye X,Y,Z (metres, scene frame); default: the scene's default view");
      command->callback([flags] {
        driver::DepthImageCommand options;
        options.scene = flags->scene;
        options.out = flags->out;
        options.kind = flags->kind;
        if (!flags->size.empty()) options.size = parse_size(flags->size, "--size");
        if (!flags->eye.empty()) options.eye_world = driver::parse_point(flags->eye, "--eye");
        const driver::DepthImage image = driver::run_depth_image_command(options);
        std::size_t seen = 0, pixels = 0;
        for (const driver::DepthImagePart& part : image.parts) {
          pixels += part.distance_m.size();
          for (float d : part.distance_m) seen += d < 1e30f;
        }
        const glm::dvec3 eye(image.T_world_image[3]);
        std::printf("%s: %s depth image, eye (%.3f, %.3f, %.3f), %zu of %zu pixels see a surface\n",
                    flags->out.c_str(), driver::to_string(image.kind).c_str(), eye.x, eye.y, eye.z,
                    seen, pixels);
      });
    }};

}  // namespace
}  // namespace facet::cli
