#include "facet/interop/mpcdi.hpp"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>

#include "facet/interop/pfm.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "test_util.hpp"

namespace facet::interop {
namespace {

const std::string kData = std::string(FACET_SHARED_DATA_DIR) + "/warps/sgct-mpcdi/";

// The largest distance in output pixels between two warps' q_from_st over an st lattice, where
// both cover.
double max_difference_px(const Warp& a, const Warp& b, int samples = 101) {
  double worst = 0;
  for (int j = 0; j < samples; ++j) {
    for (int i = 0; i < samples; ++i) {
      const glm::dvec2 st{double(i) / (samples - 1), double(j) / (samples - 1)};
      if (a.coverage_at(st) < 0.5 || b.coverage_at(st) < 0.5) continue;
      worst = std::max(worst, glm::length(a.q_from_st(st) - b.q_from_st(st)));
    }
  }
  return worst;
}

TEST(MpcdiFrustum, RotationMatchesYawPitchRollConventions) {
  MpcdiFrustum f;
  f.yaw_deg = 30;
  const glm::dvec3 forward = R_eye_frustum(f) * glm::dvec3(0, 0, -1);
  EXPECT_NEAR(forward.x, std::sin(glm::radians(30.0)), 1e-12);  // positive yaw turns right
  f = {};
  f.pitch_deg = 20;
  EXPECT_NEAR((R_eye_frustum(f) * glm::dvec3(0, 0, -1)).y, std::sin(glm::radians(20.0)), 1e-12);
  f = {};
  f.roll_deg = 10;  // positive roll turns the image clockwise: its right edge goes down
  EXPECT_LT((R_eye_frustum(f) * glm::dvec3(1, 0, 0)).y, 0);
}

TEST(MpcdiFrustum, BaseAndRotationSurviveTheFrustum) {
  const Warp warp = test::calibrated_like_warp();
  const MpcdiFrustum f = frustum_from_base(warp.base, warp.R_eye_base);
  const glm::dmat3 R = R_eye_frustum(f);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(glm::length(R[c] - warp.R_eye_base[c]), 1e-12);
  }
  const BaseProjection base = frustum_base(f);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(base.tan_extent[k], warp.base.tan_extent[k], 1e-12);
}

TEST(MpcdiRealFiles, SgctCorrectionMeshImportsAsOffsetsOverItsFrustum) {
  const MpcdiFiles files = read_zip_file(kData + "correction_mesh.mpcdi");
  const ImportedDisplay display = import_mpcdi(files, "correction_mesh.mpcdi");
  ASSERT_EQ(display.projectors.size(), 1u);
  const Warp& warp = display.projectors[0].warp;
  EXPECT_EQ(warp.output_size, glm::ivec2(512, 540));
  EXPECT_EQ(warp.grid_size, glm::ivec2(32, 32));
  // The frustum's centre direction: yaw 326.7° (33.3° to the left), pitch 27.3°.
  const glm::dvec3 centre = warp.R_eye_base * glm::dvec3(0, 0, -1);
  EXPECT_NEAR(glm::degrees(std::atan2(centre.x, -centre.z)), 326.675157 - 360, 1e-4);
  EXPECT_NEAR(glm::degrees(std::asin(centre.y)), 27.327616, 1e-4);
  // Node (0, 0) of the PFM holds (dx, dy) = (-0.1046, 0.1261) with y up: the frustum's top-left
  // corner lands left of and above the region.
  const glm::dvec2 q = warp.q_from_st({0, 0});
  EXPECT_NEAR(q.x, -0.1046 * 512, 0.1);
  EXPECT_NEAR(q.y, -0.1261 * 540, 0.1);
  EXPECT_FALSE(warp.find_fold());
  EXPECT_NO_THROW(warp.validate());
}

TEST(MpcdiRealFiles, ZeroDistortionMeshIsTheIdentity) {
  const ImportedDisplay display =
      import_mpcdi(read_zip_file(kData + "zero_distortion_mesh.mpcdi"), "zero.mpcdi");
  const Warp& warp = display.projectors[0].warp;
  for (std::size_t k = 0; k < warp.offset_px.size(); ++k) {
    EXPECT_EQ(warp.offset_px[k], glm::vec2(0.0f));
    EXPECT_EQ(warp.coverage[k], 1.0f);
  }
}

projection_io::DisplayConfig write_display(const std::filesystem::path& folder, const Warp& warp,
                                           const projection_io::BlendMap* blend) {
  projection_io::DisplayConfig config;
  config.folder = folder;
  config.name = "roundtrip";
  projection_io::DisplayProjector projector;
  projector.name = "p0";
  projector.size = warp.output_size;
  projector.warp = "p0.warp.exr";
  projector.output.window = {0, 0, warp.output_size.x, warp.output_size.y};
  write_warp((folder / "p0.warp.exr").string(), warp);
  if (blend) {
    projector.blend = "p0.blend.exr";
    projection_io::write_blend_map((folder / "p0.blend.exr").string(), *blend);
  }
  config.projectors.push_back(projector);
  projection_io::write_display_config(config, folder / "display.json");
  return projection_io::read_display_config(folder / "display.json");
}

TEST(MpcdiRoundTrip, ExportThenImportReproducesACalibratedWarpWithin001Px) {
  test::TempFolder scratch("facet-interop-roundtrip");
  const Warp warp = test::calibrated_like_warp();
  projection_io::BlendMap blend = projection_io::BlendMap::constant(warp.output_size, 1.0f);
  for (int y = 0; y < blend.size.y; ++y) {
    for (int x = 0; x < blend.size.x; ++x) blend.at(x, y) = float(std::min(1.0, x / 200.0));
  }
  const auto config = write_display(scratch.path(), warp, &blend);
  write_zip_file(scratch.path() / "d.mpcdi", export_mpcdi(config));
  const ImportedDisplay display =
      import_mpcdi(read_zip_file(scratch.path() / "d.mpcdi"), "d.mpcdi");
  ASSERT_EQ(display.projectors.size(), 1u);
  const Warp& back = display.projectors[0].warp;
  EXPECT_EQ(back.grid_size, warp.grid_size);
  // Worst case over a 101×101 st lattice, output pixels: the PFM's 4 px node spacing and float32
  // values bound it.
  const double worst = max_difference_px(warp, back);
  EXPECT_LT(worst, 0.01);
  RecordProperty("roundtrip_max_px", std::to_string(worst));
  std::printf("round trip: max %.5f px\n", worst);
  // Every node the projector shows (its output position at least one PFM node spacing, 4 px,
  // inside the image) stays covered; MPCDI has no word for the rest.
  int inside = 0;
  for (int j = 0; j < warp.grid_size.y; ++j) {
    for (int i = 0; i < warp.grid_size.x; ++i) {
      const glm::dvec2 q =
          warp.q_from_st({double(i) / (warp.grid_size.x - 1), double(j) / (warp.grid_size.y - 1)});
      if (q.x < 4 || q.y < 4 || q.x > warp.output_size.x - 4 || q.y > warp.output_size.y - 4) {
        continue;
      }
      ++inside;
      EXPECT_EQ(back.coverage[back.node_index(i, j)], 1.0f) << i << "," << j;
    }
  }
  EXPECT_GT(inside, 500);
  // Blend: 16-bit PNG, so within one code value (1/65535) plus the resampling at pixel centres,
  // which is exact at the same size.
  ASSERT_TRUE(display.projectors[0].blend);
  const auto& alpha = *display.projectors[0].blend;
  for (int y = 0; y < blend.size.y; y += 7) {
    for (int x = 0; x < blend.size.x; x += 5) {
      EXPECT_NEAR(alpha.at(x, y), blend.at(x, y), 1.0 / 65535) << x << "," << y;
    }
  }
}

TEST(MpcdiRoundTrip, WithoutFacetsGridHintTheImportStillFollowsTheWarp) {
  // A container from another tool has no facet.json: the warp is resampled on the PFM's own
  // grid, so it no longer shares the original's node lines; error stays well under 0.05 px.
  test::TempFolder scratch("facet-interop-nohint");
  const Warp warp = test::calibrated_like_warp();
  const auto config = write_display(scratch.path(), warp, nullptr);
  MpcdiExportOptions options;
  options.node_spacing_px = 8;
  MpcdiFiles files = export_mpcdi(config, options);
  files.erase("facet.json");
  const Warp back = import_mpcdi(files, "nohint.mpcdi").projectors[0].warp;
  EXPECT_EQ(back.grid_size, glm::ivec2(81, 51));
  EXPECT_LT(max_difference_px(warp, back), 0.05);
}

TEST(MpcdiRoundTrip, FisheyeBaseExportsThroughACoveringFrustum) {
  test::TempFolder scratch("facet-interop-fisheye");
  Warp warp = Warp::analytic(BaseProjection::fisheye(100), {256, 256}, {17, 17});
  const auto config = write_display(scratch.path(), warp, nullptr);
  // The fisheye is resampled into a perspective frustum twice (PFM nodes every 2 px, a 129×129
  // forward grid), so its bound is looser than a perspective warp's.
  MpcdiImportOptions options;
  options.warp_grid = glm::ivec2(129, 129);
  MpcdiExportOptions export_options;
  export_options.node_spacing_px = 2;
  const Warp back = import_mpcdi(export_mpcdi(config, export_options), "fisheye.mpcdi", options)
                        .projectors[0]
                        .warp;
  EXPECT_EQ(back.base.kind, BaseKind::perspective);
  // Compare where each eye direction lands: worst case over covered directions, output px.
  double worst = 0;
  for (int j = 1; j < 40; ++j) {
    for (int i = 1; i < 40; ++i) {
      const glm::dvec2 st{i / 40.0, j / 40.0};
      const glm::dvec3 v = warp.v_eye_from_st(st);
      const auto p = back.project(v);
      if (!p || !p->covered || glm::length(glm::dvec2(st) - 0.5) > 0.45) continue;
      worst = std::max(worst, glm::length(p->q - warp.q_from_st(st)));
    }
  }
  std::printf("fisheye through a frustum: max %.4f px\n", worst);
  EXPECT_LT(worst, 0.05);
}

// ---- crafted files ------------------------------------------------------------------------------

std::string frustum_xml(const std::string& region_attributes, const std::string& frustum,
                        const std::string& fileset, const std::string& profile = "3d") {
  return "<?xml version=\"1.0\"?><MPCDI profile=\"" + profile +
         "\" geometry=\"1\" version=\"2.0\"><display><buffer id=\"b\" xResolution=\"64\" "
         "yResolution=\"32\"><region id=\"r\" " +
         region_attributes + ">" + frustum + "</region></buffer></display><files>" + fileset +
         "</files></MPCDI>";
}
const std::string kRegion =
    "x=\"0\" y=\"0\" xSize=\"1\" ySize=\"1\" xResolution=\"64\" yResolution=\"32\"";
const std::string kFrustum =
    "<frustum><yaw>0</yaw><pitch>0</pitch><roll>0</roll><rightAngle>30</rightAngle>"
    "<leftAngle>-30</leftAngle><upAngle>20</upAngle><downAngle>-20</downAngle></frustum>";
const std::string kFileset =
    "<fileset region=\"r\"><geometryWarpFile><path>w.pfm</path><interpolation>linear"
    "</interpolation></geometryWarpFile></fileset>";

// An absolute-form identity warp over `nodes`, NaN where `hole` says so.
std::string identity_pfm(glm::ivec2 nodes, bool border_nan = false) {
  PfmImage pfm;
  pfm.width = nodes.x;
  pfm.height = nodes.y;
  for (int j = 0; j < nodes.y; ++j) {
    for (int i = 0; i < nodes.x; ++i) {
      const bool nan = border_nan && (i == 0 || j == 0 || i == nodes.x - 1 || j == nodes.y - 1);
      const float n = std::numeric_limits<float>::quiet_NaN();
      pfm.values.push_back(nan ? n : float(i) / float(nodes.x - 1));
      pfm.values.push_back(nan ? n : float(j) / float(nodes.y - 1));
      pfm.values.push_back(n);
    }
  }
  return format_pfm(pfm);
}

std::string field_of_error(const MpcdiFiles& files) {
  try {
    import_mpcdi(files, "crafted.mpcdi");
  } catch (const InputError& e) {
    return e.field();
  }
  return "no error";
}

TEST(MpcdiCrafted, NaNWarpPointsLeaveTheBorderUncovered) {
  const MpcdiFiles files{{"mpcdi.xml", frustum_xml(kRegion, kFrustum, kFileset)},
                         {"w.pfm", identity_pfm({9, 5}, true)}};
  const Warp warp = import_mpcdi(files, "nan.mpcdi").projectors[0].warp;
  // The valid nodes are the identity: at their positions the warp is exact.
  for (double s : {0.25, 0.5, 0.75}) {
    const glm::dvec2 q = warp.q_from_st({s, 0.5});
    EXPECT_NEAR(q.x, s * 64, 1e-3);
    EXPECT_NEAR(q.y, 16, 1e-3);
  }
  EXPECT_EQ(warp.coverage[0], 0.0f);
  EXPECT_GE(warp.coverage_at({0.5, 0.5}), 0.5);
}

std::string png8(int width, int height, unsigned char value) {
  std::vector<unsigned char> buffer;
  OIIO::Filesystem::IOVecOutput output(buffer);
  auto out = OIIO::ImageOutput::create("a.png", &output);
  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::UINT8);
  std::vector<unsigned char> pixels(std::size_t(width) * height, value);
  EXPECT_TRUE(out->open("a.png", spec) && out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) &&
              out->close());
  return std::string(buffer.begin(), buffer.end());
}

TEST(MpcdiCrafted, GammaEmbeddedAlphaBecomesLinear) {
  const std::string fileset =
      "<fileset region=\"r\"><geometryWarpFile><path>w.pfm</path></geometryWarpFile>"
      "<alphaMap><path>a.png</path><componentDepth>1</componentDepth><bitDepth>8</bitDepth>"
      "<gammaEmbedded>2.2</gammaEmbedded></alphaMap></fileset>";
  // The alpha map is half the region's size: it is resampled to the output.
  const MpcdiFiles files{{"mpcdi.xml", frustum_xml(kRegion, kFrustum, fileset)},
                         {"w.pfm", identity_pfm({5, 5})},
                         {"a.png", png8(32, 16, 128)}};
  const ImportedDisplay display = import_mpcdi(files, "gamma.mpcdi");
  ASSERT_TRUE(display.projectors[0].blend);
  const auto& alpha = *display.projectors[0].blend;
  EXPECT_EQ(alpha.size, glm::ivec2(64, 32));
  EXPECT_NEAR(alpha.at(10, 10), std::pow(128.0 / 255.0, 2.2), 1e-6);
}

TEST(MpcdiCrafted, RegionsWithNormalisedExtentsBecomeWindows) {
  const std::string xml =
      "<MPCDI profile=\"2d\" version=\"2.0\"><display><buffer id=\"b\" xResolution=\"2000\" "
      "yResolution=\"1000\"><region id=\"left\" x=\"0\" y=\"0\" xSize=\"0.5\" ySize=\"1\" "
      "xResolution=\"64\" yResolution=\"32\"/><region id=\"right\" x=\"0.5\" y=\"0.25\" "
      "xSize=\"0.5\" ySize=\"0.75\" xResolution=\"64\" yResolution=\"32\"/></buffer></display>"
      "<files><fileset region=\"left\"><geometryWarpFile><path>w.pfm</path></geometryWarpFile>"
      "</fileset><fileset region=\"right\"><geometryWarpFile><path>w.pfm</path>"
      "</geometryWarpFile></fileset></files></MPCDI>";
  const ImportedDisplay display =
      import_mpcdi({{"desc.xml", xml}, {"w.pfm", identity_pfm({5, 5})}}, "extents.mpcdi");
  ASSERT_EQ(display.projectors.size(), 2u);
  EXPECT_EQ(display.projectors[0].output.window, glm::ivec4(0, 0, 64, 32));
  EXPECT_EQ(display.projectors[1].output.window, glm::ivec4(1000, 250, 64, 32));
  // Profile 2d: a flat perspective base across the buffer's aspect.
  EXPECT_EQ(display.projectors[1].warp.base.tan_extent[1], 2.0);
}

TEST(MpcdiCrafted, BadContainersGiveInputErrorsNamingTheField) {
  const std::string pfm = identity_pfm({5, 5});
  EXPECT_THROW(read_zip("this is not a zip", "x.mpcdi"), InputError);
  EXPECT_EQ(field_of_error({{"w.pfm", pfm}}), "mpcdi.xml");
  EXPECT_EQ(field_of_error({{"a.xml", "<x/>"}, {"b.xml", "<x/>"}}), "mpcdi.xml");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", "<MPCDI><display>"}}), "");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, kFrustum, kFileset, "4d")}}),
            "MPCDI@profile");
  // Profile a3 reads the PFM as 3D points: this one's third channel is NaN, so no node is used.
  EXPECT_EQ(field_of_error(
                {{"mpcdi.xml", frustum_xml(kRegion, kFrustum, kFileset, "a3")}, {"w.pfm", pfm}}),
            "nodes");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml("x=\"0\" y=\"0\" ySize=\"1\" "
                                                      "xResolution=\"64\" yResolution=\"32\"",
                                                      kFrustum, kFileset)}}),
            "display/buffer[0]/region[0]@xSize");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml("x=\"0.5\" y=\"0\" xSize=\"1\" ySize=\"1\" "
                                                      "xResolution=\"64\" yResolution=\"32\"",
                                                      kFrustum, kFileset)}}),
            "display/buffer[0]/region[0]@x,y,xSize,ySize");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, "", kFileset)}}),
            "display/buffer[0]/region[0]/frustum");
  std::string flipped = kFrustum;
  flipped.replace(flipped.find("<rightAngle>30"), 14, "<rightAngle>-40");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, flipped, kFileset)}}),
            "display/buffer[0]/region[0]/frustum");
  std::string nan_yaw = kFrustum;
  nan_yaw.replace(nan_yaw.find("<yaw>0"), 6, "<yaw>nan");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, nan_yaw, kFileset)}}),
            "display/buffer[0]/region[0]/frustum/yaw");
  // Finite but beyond a turn either way: no pose, and the degrees have lost their digits.
  std::string huge_yaw = kFrustum;
  huge_yaw.replace(huge_yaw.find("<yaw>0"), 6, "<yaw>1e308");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, huge_yaw, kFileset)}}),
            "display/buffer[0]/region[0]/frustum/yaw");
  std::string turned_roll = kFrustum;
  turned_roll.replace(turned_roll.find("<roll>0"), 7, "<roll>-360.5");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, turned_roll, kFileset)}}),
            "display/buffer[0]/region[0]/frustum/roll");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, kFrustum, "")}}),
            "files/fileset[region=r]/geometryWarpFile/path");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, kFrustum, kFileset)}}),
            "files/fileset[region=r]/geometryWarpFile/path");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, kFrustum, kFileset)},
                            {"w.pfm", pfm.substr(0, pfm.size() - 4)}}),
            "data");
  PfmImage all_nan;
  all_nan.width = all_nan.height = 3;
  all_nan.values.assign(27, std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, kFrustum, kFileset)},
                            {"w.pfm", format_pfm(all_nan)}}),
            "values");
  // A mirrored warp reads neither as absolute positions nor as offsets.
  PfmImage mirrored = parse_pfm(pfm, "m");
  for (std::size_t k = 0; k < mirrored.values.size(); k += 3) {
    mirrored.values[k] = 1 - mirrored.values[k];
  }
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, kFrustum, kFileset)},
                            {"w.pfm", format_pfm(mirrored)}}),
            "values");
  const std::string alpha_fileset =
      "<fileset region=\"r\"><geometryWarpFile><path>w.pfm</path></geometryWarpFile>"
      "<alphaMap><path>a.png</path></alphaMap></fileset>";
  EXPECT_EQ(field_of_error({{"mpcdi.xml", frustum_xml(kRegion, kFrustum, alpha_fileset)},
                            {"w.pfm", pfm},
                            {"a.png", "not a png"}}),
            "a.png");
}

}  // namespace
}  // namespace facet::interop
