// Offset maps: files, validation, folds and bad values.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "facet/projection/errors.hpp"
#include "facet/projection_io/warp_file.hpp"
#include "test_displays.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

class WarpFile : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = facet::test_paths::scratch_path(
        std::string("facet-warp-test-") +
        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }
  fs::path folder_;
};

TEST_F(WarpFile, RoundTripKeepsEveryField) {
  Warp warp = test::with_smooth_offsets(
      Warp::analytic(BaseProjection::cylindrical(-150, 150, 0.8, -0.5), {1920, 1200}), {33, 17}, 5);
  warp.coverage[3] = 0.0f;
  warp.R_eye_base = glm::dmat3(glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0), glm::dvec3(1, 0, 0));
  warp.eye = glm::dvec3(0, 1.2, 0.5);
  const std::string path = (folder_ / "p0.warp.exr").string();
  write_warp(path, warp);
  const Warp back = read_warp(path);
  EXPECT_EQ(back.base.kind, BaseKind::cylindrical);
  EXPECT_EQ(back.base.azimuth_deg, warp.base.azimuth_deg);
  EXPECT_EQ(back.base.tan_elevation, warp.base.tan_elevation);
  EXPECT_EQ(back.output_size, warp.output_size);
  EXPECT_EQ(back.grid_size, warp.grid_size);
  ASSERT_EQ(back.offset_px.size(), warp.offset_px.size());
  for (std::size_t k = 0; k < warp.offset_px.size(); ++k) {
    EXPECT_EQ(back.offset_px[k], warp.offset_px[k]) << k;  // float32 stored exactly
    EXPECT_EQ(back.coverage[k], warp.coverage[k]) << k;
  }
  EXPECT_EQ(back.R_eye_base, warp.R_eye_base);
  ASSERT_TRUE(back.eye.has_value());
  EXPECT_EQ(*back.eye, *warp.eye);
  // Nothing but the file itself is left in the folder.
  EXPECT_EQ(std::distance(fs::directory_iterator(folder_), fs::directory_iterator()), 1);
}

TEST_F(WarpFile, EveryBaseRoundTrips) {
  for (const auto& [name, warp] : test::displays_for_tolerance_tests()) {
    SCOPED_TRACE(name);
    const std::string path = (folder_ / "w.warp.exr").string();
    write_warp(path, warp);
    const Warp back = read_warp(path);
    EXPECT_EQ(back.base.kind, warp.base.kind);
    EXPECT_EQ(back.base.tan_extent, warp.base.tan_extent);
    EXPECT_EQ(back.base.fov_deg, warp.base.fov_deg);
    EXPECT_EQ(back.base.elevation_deg, warp.base.elevation_deg);
    EXPECT_EQ(back.offset_px, warp.offset_px);
  }
}

// Writes a warp file bypassing validation, to test the reader on broken input.
void write_raw(const std::string& path, int w, int h, const std::vector<float>& rga,
               const std::string& meta) {
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "A"};
  spec.alpha_channel = 2;
  if (!meta.empty()) spec.attribute("facet:warp", meta);
  auto out = OIIO::ImageOutput::create("openexr");
  ASSERT_TRUE(out && out->open(path, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rga.data()));
  out->close();
}

const char* kMeta = R"({"format":"facet-warp/1","output_size":[100,100],"base":"perspective",)"
                    R"("tan_extent":[-1,1,1,-1]})";

std::vector<float> identity_nodes(int w, int h) {
  return std::vector<float>(std::size_t(w) * h * 3, 1.0f);
}

void expect_input_error(const std::string& path, const std::string& field_part) {
  try {
    read_warp(path);
    FAIL() << "accepted " << path;
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), path);
    EXPECT_NE(e.field().find(field_part), std::string::npos) << e.what();
  }
}

TEST_F(WarpFile, NanOrInfIsRejectedNamingTheNode) {
  const std::string path = (folder_ / "nan.warp.exr").string();
  auto nodes = identity_nodes(4, 3);
  for (std::size_t k = 0; k < nodes.size(); k += 3) nodes[k] = nodes[k + 1] = 0;
  nodes[(1 * 4 + 2) * 3 + 1] = NAN;  // node (2, 1), dy
  write_raw(path, 4, 3, nodes, kMeta);
  expect_input_error(path, "node (2, 1)");
  nodes[(1 * 4 + 2) * 3 + 1] = 0;
  nodes[(2 * 4 + 0) * 3 + 0] = INFINITY;  // node (0, 2), dx
  write_raw(path, 4, 3, nodes, kMeta);
  expect_input_error(path, "node (0, 2)");
}

TEST_F(WarpFile, FoldIsDetectedAtTheFirstBadNode) {
  const std::string path = (folder_ / "fold.warp.exr").string();
  auto nodes = identity_nodes(5, 5);
  for (std::size_t k = 0; k < nodes.size(); k += 3) nodes[k] = nodes[k + 1] = 0;
  // Node spacing is 25 px; pushing node (3, 2) 40 px left folds it over node (2, 2).
  nodes[(2 * 5 + 3) * 3 + 0] = -40;
  write_raw(path, 5, 5, nodes, kMeta);
  try {
    read_warp(path);
    FAIL() << "fold accepted";
  } catch (const InputError& e) {
    // The first cell in row-major order holding the moved node reverses at that node.
    EXPECT_NE(std::string(e.what()).find("node (3, 2)"), std::string::npos) << e.what();
  }
  Warp warp = Warp::analytic(BaseProjection::perspective(-1, 1, 1, -1), {100, 100}, {5, 5});
  warp.offset_px[warp.node_index(3, 2)].x = -40;
  ASSERT_TRUE(warp.find_fold().has_value());
  EXPECT_EQ(*warp.find_fold(), glm::ivec2(3, 2));
  warp.offset_px[warp.node_index(3, 2)].x = -20;  // squeezed, still injective
  EXPECT_FALSE(warp.find_fold().has_value());
}

TEST_F(WarpFile, MissingOrWrongMetadataIsRejected) {
  const std::string path = (folder_ / "meta.warp.exr").string();
  auto nodes = identity_nodes(2, 2);
  write_raw(path, 2, 2, nodes, "");
  expect_input_error(path, "facet:warp");
  write_raw(path, 2, 2, nodes, "{not json");
  expect_input_error(path, "facet:warp");
  write_raw(path, 2, 2, nodes,
            R"({"format":"facet-warp/2","output_size":[10,10],"base":"fisheye","fov":180})");
  expect_input_error(path, "format");
  write_raw(path, 2, 2, nodes,
            R"({"format":"facet-warp/1","output_size":[10,10],"base":"fisheye"})");
  expect_input_error(path, "fov");
  write_raw(
      path, 2, 2, nodes,
      R"({"format":"facet-warp/1","output_size":[10,10],"base":"perspective","tan_extent":[-1e400,1,1,-1]})");
  expect_input_error(path, "");
  expect_input_error((folder_ / "missing.warp.exr").string(), "");
}

TEST_F(WarpFile, FailedWriteLeavesNothingBehind) {
  Warp warp = Warp::analytic(BaseProjection::fisheye(180), {64, 64}, {3, 3});
  warp.offset_px[4].x = NAN;
  const std::string path = (folder_ / "bad.warp.exr").string();
  EXPECT_THROW(write_warp(path, warp), InputError);
  EXPECT_TRUE(fs::is_empty(folder_));
}

TEST(Warp, SizesBeyondTheImageLimitsAreInputErrors) {
  for (const glm::ivec2 size :
       {glm::ivec2(0, 10), glm::ivec2(10, -1), glm::ivec2(kMaxImageSide + 1, 2),
        glm::ivec2(2, kMaxImageSide + 1), glm::ivec2(8193, 8192)}) {
    EXPECT_THROW(check_image_size(size, "test", "size"), InputError) << size.x << "x" << size.y;
    EXPECT_THROW(Warp::analytic(BaseProjection::fisheye(180), size).validate("test"), InputError)
        << size.x << "x" << size.y;
  }
  for (const glm::ivec2 size : {glm::ivec2(1, 1), glm::ivec2(kMaxImageSide, 4096),
                                glm::ivec2(8192, 8192), glm::ivec2(7680, 4320)})
    EXPECT_NO_THROW(check_image_size(size, "test", "size")) << size.x << "x" << size.y;
}

}  // namespace
}  // namespace facet
