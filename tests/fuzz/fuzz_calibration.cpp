// Fuzz entry points of the calibration readers: capture.json, mrcal .cameramodel files and the
// capture's frame images.
#include <glm/glm.hpp>

#include "facet/calibration/camera_model.hpp"
#include "facet/calibration/capture.hpp"
#include "facet/calibration/image_io.hpp"
#include "facet/projection/errors.hpp"
#include "fuzz_target.hpp"

namespace {
using facet::fuzz::write_scratch;
}  // namespace

// The camera model it names is missing from the scratch folder, so validation ends there.
FACET_FUZZ_TARGET(capture_json) {
  try {
    facet::calibration::read_capture(write_scratch("capture.json", bytes));
  } catch (const facet::InputError&) {
  }
}

// A model that reads must also project and unproject without reaching an mrcal assertion.
FACET_FUZZ_TARGET(cameramodel) {
  try {
    const auto model =
        facet::calibration::CameraModel::read(write_scratch("fuzz.cameramodel", bytes));
    const glm::dvec2 centre = glm::dvec2(model.imager_size()) * 0.5;
    model.unproject(centre);
    model.project(glm::dvec3(0.1, -0.2, 1.0));
    model.is_valid_pixel(centre);
  } catch (const facet::InputError&) {
  }
}

// A capture frame (PNG or EXR, named by its first bytes as OpenImageIO picks a reader by the
// extension first): header, then the luminance every decoder reads.
FACET_FUZZ_TARGET(capture_image) {
  const bool exr = bytes.size() >= 4 && bytes[0] == 0x76 && bytes[1] == 0x2f && bytes[2] == 0x31 &&
                   bytes[3] == 0x01;
  try {
    const auto path = write_scratch(exr ? "frame.exr" : "frame.png", bytes);
    facet::calibration::read_image_info(path);
    facet::calibration::read_luminance(path);
  } catch (const facet::InputError&) {
  }
}
