#include "facet/calibration/fake_camera.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "facet/projection/errors.hpp"
#include "facet/projection_io/rig_file.hpp"
#include "facet/projection_io/warp_file.hpp"

namespace facet::calibration {

FakeCamera::FakeCamera(Rig rig, const std::vector<CaptureProjector>& projectors, ShownImage shown,
                       std::string source)
    : rig_(std::move(rig)),
      model_((rig_.validate(source), rig_camera_model(rig_.camera, source))),
      shown_(std::move(shown)) {
  FACET_ASSERT(shown_ != nullptr);
  for (const CaptureProjector& projector : projectors) {
    std::size_t index = rig_.projectors.size();
    for (std::size_t k = 0; k < rig_.projectors.size(); ++k) {
      if (rig_.projectors[k].name == projector.name) index = k;
    }
    if (index == rig_.projectors.size()) {
      std::string names;
      for (const ProjectorModel& p : rig_.projectors) names += (names.empty() ? "" : ", ") + p.name;
      throw InputError(source, "projectors",
                       "a projector named '" + projector.name +
                           "' (the display's), but the rig has only: " + names);
    }
    const glm::ivec2 size = rig_.projectors[index].size;
    if (size != projector.size) {
      throw InputError(source, "projectors[" + std::to_string(index) + "].size",
                       "the size of the display's projector '" + projector.name + "' (" +
                           std::to_string(projector.size.x) + "x" +
                           std::to_string(projector.size.y) + "), but it is " +
                           std::to_string(size.x) + "x" + std::to_string(size.y));
    }
    rig_index_.push_back(index);
    views_.push_back(view_projector(rig_, model_, index));
  }
}

glm::ivec2 FakeCamera::size() const { return model_.imager_size(); }

cv::Mat FakeCamera::grab(const GrabKey& key) {
  FACET_ASSERT(key.projector < rig_index_.size());
  cv::Mat image = ambient_image(rig_, size());
  for (std::size_t p = 0; p < rig_index_.size(); ++p) {
    const cv::Mat values = shown_(p);
    // A dark output adds no light: skipping it keeps the sum exactly simulate's.
    if (values.empty() || cv::countNonZero(values) == 0) continue;
    add_projector_light(rig_, views_[p], rig_index_[p], values, image);
  }
  finish_camera_image(rig_, image, rig_index_[key.projector], key.frame, key.repeat);
  // The sensor's quantisation, as simulate's PNG levels.
  const double levels = rig_.simulation.bits == 8 ? 255.0 : 65535.0;
  cv::Mat clamped = cv::min(cv::max(image, 0.0), 1.0);
  cv::Mat counts;
  clamped.convertTo(counts, rig_.simulation.bits == 8 ? CV_8U : CV_16U, levels);
  cv::Mat out;
  counts.convertTo(out, CV_32F, 1.0 / levels);
  return out;
}

nlohmann::json FakeCamera::identity() const {
  return {{"fake", nlohmann::json::parse(format_rig(rig_))}};
}

std::filesystem::path FakeCamera::write_truth(const std::filesystem::path& folder) const {
  const std::filesystem::path truth = folder / "truth";
  std::filesystem::create_directories(truth);
  for (const std::size_t index : rig_index_) {
    const Warp warp = true_warp(rig_, index);
    write_warp((truth / (rig_.projectors[index].name + ".warp.exr")).string(), warp);
  }
  write_rig(truth / "rig.json", rig_);
  return "truth";
}

}  // namespace facet::calibration
