#pragma once
// A camera lens model, read from and written to mrcal .cameramodel files and evaluated with the
// mrcal C library, so every lens model mrcal supports works (CAHVORE projects but does not
// unproject).
//
// Camera pixels follow mrcal: the centre of pixel (i, j) is at q = (i, j). The camera frame is
// mrcal's and OpenCV's: x right, y down, z forward.
#include <array>
#include <filesystem>
#include <glm/glm.hpp>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace facet::calibration {

class CameraModel {
 public:
  // `lensmodel` is a full mrcal name such as "LENSMODEL_OPENCV8" or
  // "LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx=30_Ny=20_fov_x_deg=170"; `intrinsics` are
  // fx, fy, cx, cy then the distortion parameters, as many as the model has. `rt_cam_ref` is
  // mrcal's extrinsics (Rodrigues rotation, then translation in metres); facet keeps it for
  // round trips but does not use it. Throws InputError(source, field, ...) on a bad name, a wrong
  // number of intrinsics, non-finite values or a non-positive imager size.
  CameraModel(const std::string& lensmodel, std::vector<double> intrinsics, glm::ivec2 imager_size,
              std::array<double, 6> rt_cam_ref = {}, const std::string& source = "camera model");

  // Reads a .cameramodel file with mrcal's C reader; also picks up `valid_intrinsics_region`,
  // which that reader skips. Throws InputError(path, ...) when the file is missing or mrcal
  // rejects it.
  static CameraModel read(const std::filesystem::path& path);

  // Writes a .cameramodel file that mrcal reads back, in full precision and with the
  // valid-intrinsics region when there is one (atomically). Throws InputError when the file
  // cannot be written.
  void write(const std::filesystem::path& path) const;

  const std::string& lensmodel() const;
  const std::vector<double>& intrinsics() const;
  glm::ivec2 imager_size() const;  // width, height in pixels
  const std::array<double, 6>& rt_cam_ref() const;
  // The polygon of pixels where the intrinsics are trustworthy (mrcal's valid_intrinsics_region);
  // empty when the file had none.
  const std::vector<glm::dvec2>& valid_intrinsics_region() const;
  void set_valid_intrinsics_region(std::vector<glm::dvec2> polygon);
  // True when q lies inside (or on) the valid region and the imager; without a region, inside
  // the imager [-0.5, W-0.5] x [-0.5, H-0.5].
  bool is_valid_pixel(glm::dvec2 q_camera) const;

  // Unit direction in the camera frame of camera pixel q. nullopt where mrcal finds no direction
  // (its solver fails, or the result is not finite) or the model is CAHVORE. Outside the imager
  // the model is extrapolated, as mrcal does.
  std::optional<glm::dvec3> unproject(glm::dvec2 q_camera) const;
  // Camera pixel of a camera-frame direction or point v (any length > 0). nullopt where mrcal
  // fails or the result is not finite. Points behind the camera still project for pinhole-like
  // models (mrcal's behaviour): check v.z when it matters.
  std::optional<glm::dvec2> project(glm::dvec3 v_camera) const;

  // Many at once; failures become NaN. Spans must have equal sizes.
  void unproject(std::span<const glm::dvec2> q_camera, std::span<glm::dvec3> v_camera) const;
  void project(std::span<const glm::dvec3> v_camera, std::span<glm::dvec2> q_camera) const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
  std::vector<glm::dvec2> valid_region_;
};

}  // namespace facet::calibration
