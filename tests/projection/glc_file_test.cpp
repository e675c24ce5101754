// The GLC camera file (facet-glc/1): every example of configs/glc reads, and bad input is refused
// naming the file and the field.
#include "facet/projection_io/glc_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "facet/projection/errors.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

fs::path example(const std::string& name) {
  return fs::path(FACET_SOURCE_DIR) / "configs/glc" / name;
}

TEST(GlcFile, EveryExampleReadsAsItsType) {
  const PiecewiseGlc city = read_glc_camera(example("city_cross_slit.glc.json"));
  EXPECT_EQ(city.size, glm::ivec2(1024, 320));
  ASSERT_EQ(city.pieces.size(), 1u);
  EXPECT_EQ(glc_type_name(city.pieces[0].type()), "cross-slit");
  // The slits at frame depths -4 and -1, as the file puts them.
  EXPECT_NEAR(city.pieces[0].slit_depths()[0], -4.0, 1e-9);
  EXPECT_NEAR(city.pieces[0].slit_depths()[1], -1.0, 1e-9);
  // Frame z forward: the middle pixel looks down the eye's -z, the top rows upwards.
  EXPECT_LT(glm::normalize(city.ray(512, 160)->direction).z, -0.99);
  EXPECT_GT(city.ray(512, 0)->direction.y, 0.0);
  EXPECT_GT(city.ray(1023, 160)->direction.x, 0.0);

  EXPECT_EQ(glc_type_name(read_glc_camera(example("pushbroom.glc.json")).pieces[0].type()),
            "pushbroom");
  EXPECT_EQ(glc_type_name(read_glc_camera(example("generators.glc.json")).pieces[0].type()),
            "bilinear");
  for (const char* name : {"panorama360.glc.json", "panorama270.glc.json"}) {
    const PiecewiseGlc pano = read_glc_camera(example(name));
    EXPECT_EQ(pano.size, glm::ivec2(800, 600));
    for (const Glc& piece : pano.pieces) EXPECT_EQ(glc_type_name(piece.type()), "cross-slit");
  }
  const PiecewiseGlc mirror = read_glc_camera(example("mirror_sphere.glc.json"));
  EXPECT_GT(mirror.pieces.size(), 500u);
}

std::string refusal(const std::string& camera) {
  try {
    parse_glc_camera(R"({"format": "facet-glc/1", "camera": )" + camera + "}", "c.glc.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(GlcFile, BadInputIsRefusedNamingTheField) {
  const std::string slits =
      R"("slit1": {"point": [0, 0, -1], "direction": [0, 1, 0]},
         "slit2": {"point": [0, 0, -4], "direction": [1, 0, 0]})";
  EXPECT_EQ(
      refusal(R"({"type": "cross-slit", "size": [64, 64], "plane_size": [1, 1], )" + slits + "}"),
      "(accepted)");
  EXPECT_EQ(
      refusal(R"({"type": "cross-slit", "size": [100000, 100000], "plane_size": [1, 1], )" + slits +
              "}"),
      "c.glc.json: field 'camera.size': expected an output of 1 to 16384 pixels a side and at "
      "most 64 Mpixel; got 100000x100000");
  EXPECT_EQ(refusal(R"({"type": "cross-slit", "size": [64, 64], "plane_size": [1, 1],
                        "slit1": {"point": [0, 0, -1], "direction": [0, 1, 0]},
                        "slit2": {"point": [0, 0, -4], "direction": [0, 2, 0]}})"),
            "c.glc.json: field 'camera.slit2': expected a slit not parallel to slit1");
  EXPECT_EQ(
      refusal(R"({"type": "cross-slit", "size": [64, 64], "plane_sise": [1, 1], )" + slits + "}")
          .substr(0, 40),
      "c.glc.json: field 'camera.plane_size': e");
  EXPECT_EQ(refusal(R"({"type": "fisheye", "size": [64, 64]})"),
            "c.glc.json: field 'camera.type': expected \"generators\", \"cross-slit\", "
            "\"pushbroom\", \"pinhole\", \"panorama\" or \"mirror-sphere\", got \"fisheye\"");
  EXPECT_EQ(refusal(R"({"type": "generators", "size": [64, 64], "generators": [
                  {"origin": [0, 0, 0], "direction": [0, 0, 1], "pixel": [0, 0]},
                  {"origin": [1, 0, 0], "direction": [1, 0, 0], "pixel": [64, 0]},
                  {"origin": [0, 1, 0], "direction": [0, 0, 1], "pixel": [0, 64]}]})"),
            "c.glc.json: field 'camera.generators[1].direction': expected a direction that "
            "leaves the image plane z = 0; this one is parallel to it");
  EXPECT_EQ(refusal(R"({"type": "generators", "size": [64, 64], "generators": [
                  {"origin": [0, 0, 0], "direction": [0, 0, 1], "pixel": [0, 0]},
                  {"origin": [0, 0, 0], "direction": [0, 0, 1], "pixel": [64, 0]},
                  {"origin": [0, 1, 0], "direction": [0, 0, 1], "pixel": [0, 64]}]})"),
            "c.glc.json: field 'camera.generators[1]': expected a ray other than "
            "camera.generators[0]; it is the same ray");
  EXPECT_EQ(refusal(R"({"type": "panorama", "size": [800, 600], "angle_deg": 360, "radius": 0.2,
                        "vertical_fov_deg": 90, "strips": 3})"),
            "c.glc.json: field 'camera.strips': expected 1 to 800 strips (the output's width), "
            "of at most 90 degrees each");
  EXPECT_EQ(refusal(R"({"type": "mirror-sphere", "size": [64, 64], "centre": [0, 0, -3],
                        "radius": 1, "fov_deg": 50, "rings": 100000})"),
            "c.glc.json: field 'camera.rings': expected 2 to 512 rings");
  try {
    parse_glc_camera(R"({"format": "facet-rig/1", "camera": {}})", "c.glc.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "format");
  }
}

}  // namespace
}  // namespace facet
