#pragma once
// The fake camera of live capture (`facet capture --camera fake:RIG.json`): a LiveCamera that sees
// the virtual rig (projection/rig.hpp) lit by whatever the projector outputs actually show. It
// forms each exposure with the image formation of `facet simulate` (simulate.hpp: gamma, defocus,
// geometry, falloff, ambient, camera blur, noise), from the images read back from the outputs
// rather than from the patterns, then quantises it to the rig's bits as a sensor would. Noise is
// seeded by (rig seed, rig projector, frame, repeat), so a capture is reproducible, and a frame of
// one exposure shown exactly (gray, white, black) equals simulate's frame bit for bit.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "facet/calibration/live_capture.hpp"
#include "facet/calibration/simulate.hpp"
#include "facet/projection/rig.hpp"

namespace facet::calibration {

class FakeCamera : public LiveCamera {
 public:
  // What capture projector p's output shows now: CV_32F of the projector's size, values in [0,1]
  // as displayed (before the projector's gamma); an empty Mat for an output showing nothing.
  using ShownImage = std::function<cv::Mat(std::size_t projector)>;

  // Capture projectors are matched to the rig's by name and must have the rig projector's size;
  // rig projectors the capture does not name stay dark. Throws InputError(source, field, ...)
  // when the rig is invalid or a capture projector is not in it or differs in size.
  FakeCamera(Rig rig, const std::vector<CaptureProjector>& projectors, ShownImage shown,
             std::string source = "rig");

  glm::ivec2 size() const override;
  // The camera image of what every output shows now, CV_32F in [0,1], quantised to the rig's
  // bits (rig.simulation.bits).
  cv::Mat grab(const GrabKey& key) override;
  // {"fake": the rig as JSON}.
  nlohmann::json identity() const override;

  const Rig& rig() const { return rig_; }
  const CameraModel& model() const { return model_; }
  // Writes `folder`/truth/<projector>.warp.exr (true_warp, FORMATS.md §5) for every capture
  // projector and truth/rig.json; returns "truth".
  std::filesystem::path write_truth(const std::filesystem::path& folder) const;

 private:
  Rig rig_;
  CameraModel model_;
  std::vector<std::size_t> rig_index_;  // capture projector → rig projector
  std::vector<ProjectorView> views_;    // per capture projector
  ShownImage shown_;
};

}  // namespace facet::calibration
