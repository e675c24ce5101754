#include "facet/interop/lookup.hpp"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/memory_budget.hpp"
#include "facet/projection/warp_inverse.hpp"
#include "json_fields.hpp"

namespace facet::interop {

void write_lookup(const Warp& warp, const std::filesystem::path& path) {
  const Activity activity("writing the lookup " + path.string());
  // Per output pixel: its st (two doubles), the image's 7 floats, and the inverse's own tables
  // (about as much again as st).
  const std::uint64_t pixels_count = std::uint64_t(warp.output_size.x) * warp.output_size.y;
  require_memory(pixels_count * (2 * 16 + 7 * 4), path.string(), "output_size",
                 "a lookup of " + std::to_string(warp.output_size.x) + "x" +
                     std::to_string(warp.output_size.y) + " pixels");
  const WarpInverse inverse(warp);
  const std::vector<glm::dvec2> st = inverse.st_at_pixel_centres();
  const int w = warp.output_size.x, h = warp.output_size.y;
  constexpr int kChannels = 7;
  std::vector<float> pixels(std::size_t(w) * h * kChannels);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t k = 0; k < st.size(); ++k) {
    float* p = &pixels[k * kChannels];
    const bool covered = std::isfinite(st[k].x) && std::isfinite(st[k].y);
    const glm::dvec3 v = covered ? warp.v_eye_from_st(st[k]) : glm::dvec3(nan);
    p[0] = float(st[k].x);
    p[1] = float(st[k].y);
    p[2] = 0.0f;
    p[3] = covered ? 1.0f : 0.0f;
    p[4] = float(v.x);
    p[5] = float(v.y);
    p[6] = float(v.z);
  }
  nlohmann::json base = {{"base", to_string(warp.base.kind)}};
  json_fields::put_base_parameters(warp.base, base);
  base["rotation"] = json_fields::from_dmat3(warp.R_eye_base);
  base["output_size"] = {w, h};
  const nlohmann::json header = {{"format", "facet-lookup/1"}, {"warp", base}};

  write_atomically(path, [&](const std::filesystem::path& temporary) {
    OIIO::ImageSpec spec(w, h, kChannels, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B", "A", "X", "Y", "Z"};
    spec.alpha_channel = 3;
    spec.attribute("compression", "zip");
    spec.attribute("facet:lookup", header.dump());
    auto out = OIIO::ImageOutput::create(temporary.string());
    if (!out || !out->open(temporary.string(), spec) ||
        !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !out->close()) {
      const std::string reason = out ? out->geterror() : OIIO::geterror();
      throw InputError(path.string(), "", "cannot write the lookup image: " + reason);
    }
  });
}

}  // namespace facet::interop
