#include "facet/calibration/image_io.hpp"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "facet/projection/atomic_file.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection_io/exr_header.hpp"

namespace facet::calibration {
namespace {

// OpenImageIO premultiplies colour by alpha on read unless told the file's alpha is unassociated;
// capture images carry light in their colour channels, whatever the alpha says.
OIIO::ImageSpec unassociated_config() {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  return config;
}

// The most pixels one byte of a file can stand for: a 1-bit PNG (8 pixels a byte) at deflate's
// largest ratio, 1032:1. OpenEXR's compressions reach less.
constexpr std::uintmax_t kMaxPixelsPerByte = 8 * 1032;

// Opens `path` once its header is known to ask for no more than the file can hold: OpenEXR
// allocates every header attribute at the size the file gives (check_exr_header walks it first,
// as for warps and blend maps), and the image size is within kMaxImageSide and kMaxImagePixels
// and what the file's bytes can encode, before any pixel is allocated.
std::unique_ptr<OIIO::ImageInput> open_image(const std::filesystem::path& path) {
  require_regular_file(path);
  projection_io::check_exr_header(path.string());
  const OIIO::ImageSpec config = unassociated_config();
  auto input = OIIO::ImageInput::open(path.string(), &config);
  if (!input) {
    throw InputError(path.string(), "", "a readable PNG or EXR image (" + OIIO::geterror() + ")");
  }
  const OIIO::ImageSpec& spec = input->spec();
  const glm::ivec2 size{spec.width, spec.height};
  check_image_size(size, path.string(), "image size");
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && std::uintmax_t(size.x) * std::uintmax_t(size.y) > bytes * kMaxPixelsPerByte) {
    throw InputError(path.string(), "image size",
                     std::to_string(size.x) + "x" + std::to_string(size.y) +
                         " pixels, more than its " + std::to_string(bytes) +
                         " bytes can encode (at most " + std::to_string(kMaxPixelsPerByte) +
                         " pixels a byte)");
  }
  return input;
}

}  // namespace

ImageInfo read_image_info(const std::filesystem::path& path) {
  auto input = open_image(path);
  const OIIO::ImageSpec& spec = input->spec();
  return {{spec.width, spec.height}, spec.nchannels, input->format_name()};
}

cv::Mat read_luminance(const std::filesystem::path& path) {
  auto input = open_image(path);
  const OIIO::ImageSpec spec = input->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1) {
    throw InputError(path.string(), "", "a 2D image with at least one channel");
  }
  // Only the channels luminance needs are read: R, G, B, or the first (grey + alpha has two).
  const bool rgb = spec.nchannels >= 3;
  const int channels = rgb ? 3 : 1;
  std::vector<float> pixels(std::size_t(spec.width) * spec.height * channels);
  // Integer pixels are converted to float in [0,1] by OpenImageIO (value / max of the type).
  if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    throw InputError(path.string(), "", "a readable image (" + input->geterror() + ")");
  }
  cv::Mat luminance(spec.height, spec.width, CV_32F);
  for (int y = 0; y < spec.height; ++y) {
    auto* row = luminance.ptr<float>(y);
    const float* in = pixels.data() + std::size_t(y) * spec.width * channels;
    for (int x = 0; x < spec.width; ++x, in += channels) {
      row[x] = rgb ? 0.2126f * in[0] + 0.7152f * in[1] + 0.0722f * in[2] : in[0];
    }
  }
  return luminance;
}

void write_grey_image(const std::filesystem::path& path, const cv::Mat& image, int bit_depth) {
  FACET_ASSERT(image.type() == CV_32F && !image.empty());
  const bool exr = path.extension() == ".exr";
  FACET_ASSERT(exr || bit_depth == 8 || bit_depth == 16);
  const OIIO::TypeDesc file_type =
      exr ? OIIO::TypeDesc::FLOAT
          : (bit_depth == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  OIIO::ImageSpec spec(image.cols, image.rows, 1, file_type);
  spec.attribute("oiio:UnassociatedAlpha", 1);
  cv::Mat clamped;
  cv::Mat contiguous = image.isContinuous() ? image : image.clone();
  if (exr) {
    clamped = contiguous;
  } else {
    // Round to the nearest level ourselves: OpenImageIO's float to integer conversion would do
    // the same, but an explicit rounding makes the quantisation of the file well defined.
    const double levels = bit_depth == 8 ? 255.0 : 65535.0;
    cv::Mat scaled = cv::min(cv::max(contiguous, 0.0), 1.0);
    scaled.convertTo(clamped, bit_depth == 8 ? CV_8U : CV_16U, levels);  // saturate_cast rounds
  }
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    auto output = OIIO::ImageOutput::create(temporary.string());
    if (!output || !output->open(temporary.string(), spec)) {
      throw InputError(path.string(), "", "a writable image file (" + OIIO::geterror() + ")");
    }
    if (!output->write_image(file_type, clamped.data) || !output->close()) {
      throw InputError(path.string(), "", "a writable image file (" + output->geterror() + ")");
    }
  });
}

void write_rgb_image(const std::filesystem::path& path, const cv::Mat& rgb) {
  FACET_ASSERT(rgb.type() == CV_8UC3 && !rgb.empty());
  const cv::Mat contiguous = rgb.isContinuous() ? rgb : rgb.clone();
  const OIIO::ImageSpec spec(rgb.cols, rgb.rows, 3, OIIO::TypeDesc::UINT8);
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    auto output = OIIO::ImageOutput::create(temporary.string());
    if (!output || !output->open(temporary.string(), spec)) {
      throw InputError(path.string(), "", "a writable image file (" + OIIO::geterror() + ")");
    }
    if (!output->write_image(OIIO::TypeDesc::UINT8, contiguous.data) || !output->close()) {
      throw InputError(path.string(), "", "a writable image file (" + output->geterror() + ")");
    }
  });
}

}  // namespace facet::calibration
