// MPCDI profile a3 (warps as 3D screen points): round trips, the eye point, crafted files, and
// the base rotation stored as rows by every facet file that records it.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "facet/interop/lookup.hpp"
#include "facet/interop/mpcdi.hpp"
#include "facet/interop/pfm.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "test_util.hpp"

namespace facet::interop {
namespace {

// The largest distance in output pixels between two warps' q_from_st over an st lattice, where
// both cover.
// With `interior_cells` > 0, only st whose neighbours that many cells of `a`'s grid away (in
// s and t) are covered by `a` too count.
double max_difference_px(const Warp& a, const Warp& b, int samples = 101, int interior_cells = 0) {
  double worst = 0;
  const glm::dvec2 reach = double(interior_cells) / glm::dvec2(a.grid_size - 1);
  for (int j = 0; j < samples; ++j) {
    for (int i = 0; i < samples; ++i) {
      const glm::dvec2 st{double(i) / (samples - 1), double(j) / (samples - 1)};
      if (a.coverage_at(st) < 0.5 || b.coverage_at(st) < 0.5) continue;
      bool interior = true;
      for (int dj = -1; dj <= 1 && interior_cells > 0; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const glm::dvec2 near = st + glm::dvec2(di, dj) * reach;
          interior = interior && near.x >= 0 && near.y >= 0 && near.x <= 1 && near.y <= 1 &&
                     a.coverage_at(near) >= 0.5;
        }
      }
      if (!interior) continue;
      worst = std::max(worst, glm::length(a.q_from_st(st) - b.q_from_st(st)));
    }
  }
  return worst;
}

// Fraction of an st lattice covered by `original` whose output lies at least `margin_px` inside
// the image and which `back` covers too.
double covered_fraction(const Warp& original, const Warp& back, double margin_px) {
  int inside = 0, kept = 0;
  for (int j = 0; j <= 60; ++j) {
    for (int i = 0; i <= 60; ++i) {
      const glm::dvec2 st{i / 60.0, j / 60.0};
      if (original.coverage_at(st) < 0.5) continue;
      const glm::dvec2 q = original.q_from_st(st);
      if (q.x < margin_px || q.y < margin_px || q.x > original.output_size.x - margin_px ||
          q.y > original.output_size.y - margin_px) {
        continue;
      }
      ++inside;
      const auto p = back.project(original.v_eye_from_st(st));
      kept += p && p->covered;
    }
  }
  return inside ? double(kept) / inside : 0.0;
}

projection_io::DisplayConfig one_projector_display(const std::filesystem::path& folder,
                                                   const Warp& warp) {
  projection_io::DisplayConfig config;
  config.folder = folder;
  config.name = "a3";
  projection_io::DisplayProjector projector;
  projector.name = "p0";
  projector.size = warp.output_size;
  projector.warp = "p0.warp.exr";
  projector.output.window = {0, 0, warp.output_size.x, warp.output_size.y};
  write_warp((folder / "p0.warp.exr").string(), warp);
  config.projectors.push_back(projector);
  projection_io::write_display_config(config, folder / "display.json");
  return projection_io::read_display_config(folder / "display.json");
}

MpcdiExportOptions a3_options(double spacing = 4) {
  MpcdiExportOptions options;
  options.profile = MpcdiProfile::advanced_3d;
  options.node_spacing_px = spacing;
  return options;
}

TEST(MpcdiA3, ExportWritesScreenPointsInTheFilesAxes) {
  test::TempFolder scratch("facet-interop-a3-axes");
  // Identity perspective: the output centre looks straight ahead (eye −z), the right edge
  // towards +x. In the file's axes (x left, z into the screen) those are +z and −x.
  const Warp warp = Warp::analytic(BaseProjection::perspective(-1, 1, 0.75, -0.75), {64, 48});
  const MpcdiFiles files = export_mpcdi(one_projector_display(scratch.path(), warp), a3_options(8));
  const MpcdiDocument document = parse_mpcdi_xml(files.at("mpcdi.xml"), "a3.xml");
  EXPECT_EQ(document.profile, MpcdiProfile::advanced_3d);
  EXPECT_EQ(document.regions[0].unit, MpcdiUnit::m);
  EXPECT_EQ(document.regions[0].origin, MpcdiOrigin::ideal_eye_point);
  EXPECT_FALSE(document.regions[0].frustum);
  const PfmImage pfm = parse_pfm(files.at("p0.pfm"), "p0.pfm");
  ASSERT_EQ(pfm.width, 9);
  ASSERT_EQ(pfm.height, 7);
  // Unit sphere around the eye (no screen in display.json).
  EXPECT_NEAR(pfm.at(4, 3, 0), 0, 1e-6);
  EXPECT_NEAR(pfm.at(4, 3, 1), 0, 1e-6);
  EXPECT_NEAR(pfm.at(4, 3, 2), 1, 1e-6);
  EXPECT_NEAR(pfm.at(8, 3, 0), -std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(pfm.at(8, 3, 2), std::sqrt(0.5), 1e-6);
  // The top row is the first stored row (MPCDI raster order) and looks up.
  EXPECT_GT(pfm.at(4, 0, 1), 0.5);
}

TEST(MpcdiA3, RoundTripReproducesACalibratedWarpWithin001Px) {
  test::TempFolder scratch("facet-interop-a3-roundtrip");
  const Warp warp = test::calibrated_like_warp();
  const auto config = one_projector_display(scratch.path(), warp);
  write_zip_file(scratch.path() / "d.mpcdi", export_mpcdi(config, a3_options()));
  const ImportedDisplay display =
      import_mpcdi(read_zip_file(scratch.path() / "d.mpcdi"), "d.mpcdi");
  ASSERT_EQ(display.projectors.size(), 1u);
  const Warp& back = display.projectors[0].warp;
  EXPECT_EQ(back.grid_size, warp.grid_size);
  EXPECT_EQ(back.base.kind, BaseKind::perspective);
  EXPECT_TRUE(display.notes.empty());
  // Worst case over a 101×101 st lattice, output pixels.
  const double worst = max_difference_px(warp, back);
  std::printf("a3 round trip, calibrated-like warp: max %.5f px\n", worst);
  EXPECT_LT(worst, 0.01);
}

// A rotation with no symmetry: stored as columns where rows are read, it comes back transposed.
glm::dmat3 skew_rotation() {
  const double a = 0.5, b = -0.3, c = 0.2;  // radians about y, then x, then z
  const glm::dmat3 y(std::cos(a), 0, -std::sin(a), 0, 1, 0, std::sin(a), 0, std::cos(a));
  const glm::dmat3 x(1, 0, 0, 0, std::cos(b), std::sin(b), 0, -std::sin(b), std::cos(b));
  const glm::dmat3 z(std::cos(c), std::sin(c), 0, -std::sin(c), std::cos(c), 0, 0, 0, 1);
  return y * x * z;
}

// The JSON header attribute `name` of an EXR file.
nlohmann::json exr_json(const std::filesystem::path& path, const char* name) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return nullptr;
  return nlohmann::json::parse(in->spec().get_string_attribute(name));
}

// Every facet file that records a base's rotation (the warp's facet:warp header, the lookup
// export's facet:lookup, an a3 container's facet.json) stores R_eye_base as a list of rows, and
// each reads back the same matrix: exactly for the warp file and facet.json (JSON keeps every
// double), and the a3 import lands on the same base (under 0.01 px) from facet.json's rows and
// from the columns earlier containers stored.
TEST(MpcdiA3, BaseRotationIsStoredAsRowsEverywhereAndRoundTrips) {
  test::TempFolder scratch("facet-interop-a3-rotation");
  const glm::dmat3 R = skew_rotation();
  ASSERT_GT(std::abs(R[0][1] - R[1][0]), 0.1);  // not symmetric
  const Warp warp =
      Warp::analytic(BaseProjection::perspective(-0.6, 0.6, 0.45, -0.45), {400, 300}, {33, 25}, R);
  const auto rows_of = [](const nlohmann::json& rotation) {
    glm::dmat3 m(0.0);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[c][r] = rotation.at(r).at(c).get<double>();
    return m;
  };

  const auto config = one_projector_display(scratch.path(), warp);
  EXPECT_EQ(rows_of(exr_json(scratch.path() / "p0.warp.exr", "facet:warp")["rotation"]), R);
  EXPECT_EQ(read_warp((scratch.path() / "p0.warp.exr").string()).R_eye_base, R);

  write_lookup(warp, scratch.path() / "lookup.exr");
  EXPECT_EQ(rows_of(exr_json(scratch.path() / "lookup.exr", "facet:lookup")["warp"]["rotation"]),
            R);

  MpcdiFiles files = export_mpcdi(config, a3_options(2));
  nlohmann::json hints = nlohmann::json::parse(files.at("facet.json"));
  nlohmann::json& base = hints["regions"]["p0"]["base"];
  EXPECT_EQ(rows_of(base["rotation"]), R);
  const Warp back = import_mpcdi(files, "rotation.mpcdi").projectors[0].warp;
  EXPECT_EQ(back.R_eye_base, R);
  EXPECT_LT(max_difference_px(warp, back), 0.01);

  // A container from before: the same rotation as columns, under its old name.
  nlohmann::json columns = nlohmann::json::array();
  for (int c = 0; c < 3; ++c) columns.push_back({R[c].x, R[c].y, R[c].z});
  base.erase("rotation");
  base["rotation_columns"] = columns;
  files["facet.json"] = hints.dump();
  const Warp old = import_mpcdi(files, "old.mpcdi").projectors[0].warp;
  EXPECT_EQ(old.R_eye_base, R);
  EXPECT_LT(max_difference_px(warp, old), 0.01);
}

TEST(MpcdiA3, FisheyeAndCylindricalBasesGoThroughAsTheyAre) {
  test::TempFolder scratch("facet-interop-a3-bases");
  // 3d export needs a covering frustum for these; a3 carries them unchanged.
  for (const BaseProjection& base :
       {BaseProjection::fisheye(200), BaseProjection::cylindrical(-100, 100, 0.8, -0.6)}) {
    const Warp warp = Warp::analytic(base, {400, 300}, {33, 25});
    const auto config = one_projector_display(scratch.path() / to_string(base.kind), [&] {
      std::filesystem::create_directories(scratch.path() / to_string(base.kind));
      return warp;
    }());
    const Warp back =
        import_mpcdi(export_mpcdi(config, a3_options(2)), "bases.mpcdi").projectors[0].warp;
    EXPECT_EQ(back.base.kind, base.kind);
    const double worst = max_difference_px(warp, back);
    std::printf("a3 round trip, %s base: max %.5f px\n", to_string(base.kind).c_str(), worst);
    EXPECT_LT(worst, 0.01) << to_string(base.kind);
  }
}

TEST(MpcdiA3, SampleDomeRoundTripsWithin001PxWhereverBothCover) {
  // The calibrated sample display: four projectors, a 5 m dome screen, so the PFM holds points on
  // the dome rather than on the unit sphere.
  const auto config = projection_io::read_display_config(std::string(FACET_SOURCE_DIR) +
                                                         "/configs/displays/dome4/display.json");
  ASSERT_TRUE(config.screen);
  const MpcdiFiles files = export_mpcdi(config, a3_options());
  const PfmImage pfm = parse_pfm(files.at("p0.pfm"), "p0.pfm");
  int on_dome = 0;
  for (int j = 0; j < pfm.height; j += 16) {
    for (int i = 0; i < pfm.width; i += 16) {
      const glm::dvec3 p{pfm.at(i, j, 0), pfm.at(i, j, 1), pfm.at(i, j, 2)};
      if (!std::isfinite(p.x)) continue;
      EXPECT_NEAR(
          glm::length(p - (glm::transpose(R_eye_mpcdi3d()) * (config.screen->center - config.eye))),
          config.screen->radius, 1e-5);
      ++on_dome;
    }
  }
  EXPECT_GT(on_dome, 100);
  const ImportedDisplay display = import_mpcdi(files, "dome4.mpcdi");
  ASSERT_EQ(display.projectors.size(), config.projectors.size());
  for (std::size_t p = 0; p < config.projectors.size(); ++p) {
    const Warp original = read_warp(config.resolve(config.projectors[p].warp).string());
    const Warp& back = display.projectors[p].warp;
    EXPECT_EQ(back.grid_size, original.grid_size);
    // The dome's warps stop covering a few pixels inside their output images, and MPCDI has no
    // coverage: a PFM node that shows nothing is NaN. facet's export continues each warp one
    // node past that edge and lists those nodes in facet.json, so that the import pins the
    // forward cells across the edge (without them: 0.0019-0.022 px there) but does not show them
    // (read as shown they would add 0.7-0.8% coverage).
    const double interior = max_difference_px(original, back, 201, 2);
    const double everywhere = max_difference_px(original, back, 201);
    const double kept = covered_fraction(original, back, 4);
    const double added = 1 - covered_fraction(back, original, 4);
    std::printf(
        "a3 round trip, dome4 %s: max %.5f px two cells inside the coverage edge, "
        "%.5f px everywhere both cover; coverage kept %.5f, added %.5f\n",
        config.projectors[p].name.c_str(), interior, everywhere, kept, added);
    EXPECT_LT(interior, 0.01) << config.projectors[p].name;
    EXPECT_LT(everywhere, 0.01) << config.projectors[p].name;
    // Every direction the projector shows at least one PFM node spacing (4 px) inside its image
    // stays covered, and the import covers no more than the original does.
    EXPECT_GT(kept, 0.999) << config.projectors[p].name;
    EXPECT_LT(added, 0.001) << config.projectors[p].name;
  }
}

TEST(MpcdiDome, SampleDomeRoundTripsThroughProfile3dToo) {
  // The same display through frusta and source positions. Before the inverse grid's guards the
  // filled-in corners of these PFMs sent interior base positions 200-600 px off.
  auto config = projection_io::read_display_config(std::string(FACET_SOURCE_DIR) +
                                                   "/configs/displays/dome4/display.json");
  // One projector (the a3 test above covers all four): p0 has the widest uncovered corners.
  config.projectors.resize(1);
  const ImportedDisplay display = import_mpcdi(export_mpcdi(config), "dome4.mpcdi");
  for (std::size_t p = 0; p < config.projectors.size(); ++p) {
    const Warp original = read_warp(config.resolve(config.projectors[p].warp).string());
    const Warp& back = display.projectors[p].warp;
    const double interior = max_difference_px(original, back, 201, 2);
    const double everywhere = max_difference_px(original, back, 201);
    const double kept = covered_fraction(original, back, 4);
    const double added = 1 - covered_fraction(back, original, 4);
    std::printf(
        "3d round trip, dome4 %s: max %.5f px two cells inside the coverage edge, %.5f px "
        "everywhere both cover; coverage kept %.5f, added %.5f\n",
        config.projectors[p].name.c_str(), interior, everywhere, kept, added);
    EXPECT_LT(interior, 0.01) << config.projectors[p].name;
    EXPECT_LT(everywhere, 0.01) << config.projectors[p].name;
    EXPECT_GT(kept, 0.999) << config.projectors[p].name;
    EXPECT_LT(added, 0.001) << config.projectors[p].name;
  }
}

TEST(MpcdiA3, OtherToolsFilesImportOnABaseOfTheirOwn) {
  // No facet.json: the import chooses a base that covers the region's directions, so compare
  // where directions land rather than base positions.
  test::TempFolder scratch("facet-interop-a3-nohint");
  const Warp warp = test::calibrated_like_warp();
  MpcdiFiles files = export_mpcdi(one_projector_display(scratch.path(), warp), a3_options(4));
  files.erase("facet.json");
  MpcdiImportOptions options;
  options.warp_grid = glm::ivec2(65, 41);
  const Warp back = import_mpcdi(files, "nohint.mpcdi", options).projectors[0].warp;
  const double worst = test::direction_difference(warp, back, 4).worst_px;
  std::printf("a3 without facet.json: max %.5f px\n", worst);
  EXPECT_LT(worst, 0.05);
  // The chosen base's margin and grid decide coverage near the image edge: measured 0.9986.
  EXPECT_GT(covered_fraction(warp, back, 4), 0.995);
}

// A region whose a3 points lie on a plane 2 m in front of an eye that is not the file's origin:
// the eye option must move the directions back to the eye.
TEST(MpcdiA3, TheEyeOptionSetsWhereDirectionsStart) {
  const Warp truth = Warp::analytic(BaseProjection::perspective(-0.8, 0.6, 0.5, -0.4), {160, 120});
  const glm::dvec3 eye_file{0.3, 1.2, -0.5};  // file frame, metres (floorCenter origin)
  PfmImage pfm;
  pfm.width = 41;
  pfm.height = 31;
  for (int j = 0; j < pfm.height; ++j) {
    for (int i = 0; i < pfm.width; ++i) {
      const glm::dvec2 q{i / 40.0 * 160, j / 30.0 * 120};
      const glm::dvec2 st{q.x / 160, q.y / 120};  // zero offsets: st is q normalised
      const glm::dvec3 v = truth.v_eye_from_st(st);
      // Along the ray to the plane 2 m ahead (eye −z), then into the file's axes.
      const glm::dvec3 p = eye_file + glm::transpose(R_eye_mpcdi3d()) * (v * (2.0 / -v.z));
      pfm.values.insert(pfm.values.end(), {float(p.x), float(p.y), float(p.z)});
    }
  }
  const std::string xml =
      "<MPCDI profile=\"a3\" version=\"2.0\"><display><buffer id=\"b\" xResolution=\"160\" "
      "yResolution=\"120\"><region id=\"r\" x=\"0\" y=\"0\" xSize=\"1\" ySize=\"1\" "
      "xResolution=\"160\" yResolution=\"120\"/></buffer></display><files><fileset "
      "region=\"r\"><geometryWarpFile><path>w.pfm</path><geometricUnit>m</geometricUnit>"
      "<interpolation>linear</interpolation><originOf3DData>floorCenter</originOf3DData>"
      "</geometryWarpFile></fileset></files></MPCDI>";
  const MpcdiFiles files{{"mpcdi.xml", xml}, {"w.pfm", format_pfm(pfm)}};
  MpcdiImportOptions options;
  options.eye = eye_file;
  options.warp_grid = glm::ivec2(65, 49);
  const ImportedDisplay display = import_mpcdi(files, "eye.mpcdi", options);
  EXPECT_TRUE(display.notes.empty());
  // The display's eye is the eye point in facet's axes: x right, z towards the viewer.
  EXPECT_NEAR(display.eye.x, -0.3, 1e-12);
  EXPECT_NEAR(display.eye.y, 1.2, 1e-12);
  EXPECT_NEAR(display.eye.z, 0.5, 1e-12);
  const double worst = test::direction_difference(truth, display.projectors[0].warp, 4).worst_px;
  std::printf("a3 plane seen from --eye: max %.5f px\n", worst);
  EXPECT_LT(worst, 0.05);
  // Without the eye, the origin is a guess the import says it made, and the directions are off.
  const ImportedDisplay guessed = import_mpcdi(files, "eye.mpcdi");
  ASSERT_EQ(guessed.notes.size(), 1u);
  EXPECT_NE(guessed.notes[0].find("the import's eye"), std::string::npos) << guessed.notes[0];
  EXPECT_GT(test::direction_difference(truth, guessed.projectors[0].warp, 4).worst_px, 5.0);
}

std::string a3_xml(const std::string& warp_children, const std::string& second_region = "") {
  return "<MPCDI profile=\"a3\" version=\"2.0\"><display><buffer id=\"b\" xResolution=\"128\" "
         "yResolution=\"32\"><region id=\"r\" x=\"0\" y=\"0\" xSize=\"0.5\" ySize=\"1\" "
         "xResolution=\"64\" yResolution=\"32\"/>" +
         std::string(second_region.empty()
                         ? ""
                         : "<region id=\"s\" x=\"0.5\" y=\"0\" xSize=\"0.5\" "
                           "ySize=\"1\" xResolution=\"64\" yResolution=\"32\"/>") +
         "</buffer></display><files><fileset region=\"r\"><geometryWarpFile><path>w.pfm</path>" +
         warp_children + "</geometryWarpFile></fileset>" +
         (second_region.empty() ? ""
                                : "<fileset region=\"s\"><geometryWarpFile><path>w.pfm</path>" +
                                      second_region + "</geometryWarpFile></fileset>") +
         "</files></MPCDI>";
}

// Points on the unit sphere in front of the origin (file axes: z into the screen).
std::string sphere_pfm(glm::ivec2 nodes) {
  PfmImage pfm;
  pfm.width = nodes.x;
  pfm.height = nodes.y;
  for (int j = 0; j < nodes.y; ++j) {
    for (int i = 0; i < nodes.x; ++i) {
      const glm::dvec3 p = glm::normalize(
          glm::dvec3(0.5 - double(i) / (nodes.x - 1), 0.5 - double(j) / (nodes.y - 1), 1));
      pfm.values.insert(pfm.values.end(), {float(p.x), float(p.y), float(p.z)});
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

TEST(MpcdiA3, CraftedFilesNameTheField) {
  const std::string good =
      "<geometricUnit>m</geometricUnit><originOf3DData>idealEyePoint"
      "</originOf3DData>";
  const std::string pfm = sphere_pfm({9, 5});
  EXPECT_EQ(field_of_error({{"mpcdi.xml", a3_xml(good)}, {"w.pfm", pfm}}), "no error");
  // The reference library's spelling of unknown, and missing elements, read as unknown.
  EXPECT_EQ(field_of_error(
                {{"mpcdi.xml", a3_xml("<geometricUnit>unkown</geometricUnit>")}, {"w.pfm", pfm}}),
            "no error");
  EXPECT_EQ(field_of_error(
                {{"mpcdi.xml", a3_xml("<geometricUnit>furlong</geometricUnit>")}, {"w.pfm", pfm}}),
            "files/fileset[region=r]/geometryWarpFile/geometricUnit");
  EXPECT_EQ(field_of_error(
                {{"mpcdi.xml", a3_xml("<originOf3DData>nose</originOf3DData>")}, {"w.pfm", pfm}}),
            "files/fileset[region=r]/geometryWarpFile/originOf3DData");
  EXPECT_EQ(field_of_error({{"mpcdi.xml", a3_xml(good,
                                                 "<geometricUnit>mm</geometricUnit><originOf3DData>"
                                                 "idealEyePoint</originOf3DData>")},
                            {"w.pfm", pfm}}),
            "files/fileset[region=s]/geometryWarpFile/geometricUnit");
  // Every node unused: NaN, or (0, 0, 0).
  PfmImage unused;
  unused.width = unused.height = 3;
  unused.values.assign(27, std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(field_of_error({{"mpcdi.xml", a3_xml(good)}, {"w.pfm", format_pfm(unused)}}), "nodes");
  unused.values.assign(27, 0.0f);
  EXPECT_EQ(field_of_error({{"mpcdi.xml", a3_xml(good)}, {"w.pfm", format_pfm(unused)}}), "nodes");
  // A one-channel PFM cannot hold points.
  PfmImage grey;
  grey.width = grey.height = 3;
  grey.channels = 1;
  grey.values.assign(9, 1.0f);
  EXPECT_EQ(field_of_error({{"mpcdi.xml", a3_xml(good)}, {"w.pfm", format_pfm(grey)}}), "header");
}

}  // namespace
}  // namespace facet::interop
