// Fuzz entry points of the driver's readers: glTF scenes, material files, the cluster's frame
// state (binary wire form and JSON) and still content images for `facet play`.
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>

#include "facet/driver/cluster.hpp"
#include "facet/driver/content_media.hpp"
#include "facet/driver/gltf_loader.hpp"
#include "facet/driver/material_shader.hpp"
#include "facet/driver/session.hpp"
#include "facet/projection/errors.hpp"
#include "fuzz_target.hpp"

namespace {
using facet::fuzz::text_of;
using facet::fuzz::write_scratch;

bool starts_with(facet::fuzz::Bytes bytes, std::string_view magic) {
  return bytes.size() >= magic.size() && std::memcmp(bytes.data(), magic.data(), magic.size()) == 0;
}
}  // namespace

// A binary glTF for input starting with its magic, else glTF JSON; buffers and images it names
// are looked up beside it in the scratch folder.
FACET_FUZZ_TARGET(gltf) {
  try {
    facet::driver::load_gltf(
        write_scratch(starts_with(bytes, "glTF") ? "fuzz.glb" : "fuzz.gltf", bytes));
  } catch (const facet::InputError&) {
  }
}

FACET_FUZZ_TARGET(material_frag) {
  try {
    const auto material =
        facet::driver::load_material_shader(write_scratch("fuzz.frag", bytes).string());
    facet::driver::material_stage_text(material.text);
  } catch (const facet::InputError&) {
  }
}

// A decoded frame state encodes to one that decodes to the same state.
FACET_FUZZ_TARGET(frame_state_wire) {
  try {
    const auto state = facet::driver::decode_frame_state(bytes, "fuzz");
    const auto again =
        facet::driver::decode_frame_state(facet::driver::encode_frame_state(state), "again");
    if (!(again == state)) std::abort();
  } catch (const facet::InputError&) {
  }
}

FACET_FUZZ_TARGET(frame_state_json) {
  const nlohmann::json value = nlohmann::json::parse(text_of(bytes), nullptr, false);
  if (value.is_discarded()) return;
  try {
    facet::driver::frame_state_from_json(value, "fuzz");
  } catch (const facet::InputError&) {
  }
}

// A still image for `facet play`, named by its magic: PNG, JPEG, else OpenEXR.
FACET_FUZZ_TARGET(content_image) {
  const char* name = starts_with(bytes, "\x89PNG")    ? "fuzz.png"
                     : starts_with(bytes, "\xff\xd8") ? "fuzz.jpg"
                                                      : "fuzz.exr";
  try {
    facet::driver::ContentMedia::open(write_scratch(name, bytes));
  } catch (const facet::InputError&) {
  }
}
