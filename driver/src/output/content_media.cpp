#include "facet/driver/content_media.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "facet/projection/errors.hpp"
#include "facet/projection/input_file.hpp"
#include "facet/projection/warp.hpp"
#include "facet/projection_io/exr_header.hpp"

namespace facet::driver {

namespace fs = std::filesystem;

struct ContentMedia::Video {
  cv::VideoCapture capture;
};

namespace {

std::string size_text(glm::ivec2 size) {
  return std::to_string(size.x) + "x" + std::to_string(size.y);
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Images and frames up to kMaxImagePixels; a side up to kMaxImageSide, or six faces of it.
void check_content_size(glm::ivec2 size, const std::string& source) {
  const bool strip = size.y > 0 && size.x == 6 * size.y;
  const int widest = strip ? 6 * kMaxImageSide : kMaxImageSide;
  if (size.x < 1 || size.y < 1 || size.x > widest || size.y > kMaxImageSide ||
      std::int64_t(size.x) * size.y > kMaxImagePixels)
    throw InputError(source, "image",
                     "an image of 1 to " + std::to_string(kMaxImageSide) +
                         " pixels a side (six faces for a cube strip) and at most " +
                         std::to_string(kMaxImagePixels) + " pixels; got " + size_text(size));
}

ContentImage read_still_image(const fs::path& path) {
  const std::string source = path.string();
  projection_io::check_exr_header(source);
  auto input = OIIO::ImageInput::open(source);
  if (!input)
    throw InputError(
        source, "image",
        "an image OpenImageIO can read (PNG, JPEG, EXR, TIFF, HDR): " + OIIO::geterror());
  const OIIO::ImageSpec& spec = input->spec();
  ContentImage image;
  image.size = {spec.width, spec.height};
  check_content_size(image.size, source);
  const int channels = spec.nchannels;
  image.channels = channels >= 4 ? 4 : channels == 3 ? 3 : 1;
  const bool is_float = spec.format.basetype == OIIO::TypeDesc::HALF ||
                        spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                        spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  const std::size_t values = std::size_t(image.size.x) * image.size.y * image.channels;
  bool read = false;
  if (is_float) {
    image.pixels = ContentImage::Pixels::linear_f32;
    image.values.resize(values);
    read = input->read_image(0, 0, 0, image.channels, OIIO::TypeDesc::FLOAT, image.values.data());
  } else {
    image.pixels = ContentImage::Pixels::srgb8;
    image.bytes.resize(values);
    read = input->read_image(0, 0, 0, image.channels, OIIO::TypeDesc::UINT8, image.bytes.data());
  }
  if (!read) throw InputError(source, "image", "a complete, readable image: " + input->geterror());
  if (is_float) {
    for (float& value : image.values)
      if (!std::isfinite(value)) value = 0;
  }
  return image;
}

}  // namespace

bool is_still_image_path(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* still : {".png", ".jpg", ".jpeg", ".exr", ".hdr", ".tif", ".tiff"})
    if (extension == still) return true;
  return false;
}

ContentMedia::~ContentMedia() = default;

std::unique_ptr<ContentMedia> ContentMedia::open(const fs::path& path) {
  const Activity activity("opening the content " + path.string());
  require_regular_file(path);
  std::unique_ptr<ContentMedia> media(new ContentMedia());
  media->path_ = path;
  if (is_still_image_path(path)) {
    media->first_ = read_still_image(path);
    return media;
  }
  const std::string source = path.string();
  media->video_ = std::make_unique<Video>();
  cv::VideoCapture& capture = media->video_->capture;
  if (!capture.open(source, cv::CAP_FFMPEG))
    throw InputError(source, "video",
                     "a video FFmpeg can open (a container and codec it knows; still images by "
                     "their extension: .png .jpg .jpeg .exr .hdr .tif .tiff); this one could not "
                     "be opened");
  const glm::ivec2 size{int(capture.get(cv::CAP_PROP_FRAME_WIDTH)),
                        int(capture.get(cv::CAP_PROP_FRAME_HEIGHT))};
  check_content_size(size, source);
  media->fps_ = capture.get(cv::CAP_PROP_FPS);
  if (!(std::isfinite(media->fps_) && media->fps_ > 0 && media->fps_ <= 1000))
    throw InputError(source, "video",
                     "a video with a frame rate in (0, 1000] frames a second; FFmpeg reports " +
                         std::to_string(media->fps_));
  const double count = capture.get(cv::CAP_PROP_FRAME_COUNT);
  media->frame_count_ =
      std::isfinite(count) && count >= 1 ? std::int64_t(count) : std::int64_t(1) << 40;
  ContentImage& first = media->first_;
  first.size = size;
  first.channels = 3;
  first.bgr = true;
  first.pixels = ContentImage::Pixels::srgb8;
  first.bytes.resize(std::size_t(size.x) * size.y * 3);
  if (!media->read_next_into(first))
    throw InputError(source, "video",
                     "a video whose frames FFmpeg can decode; not even the first frame could be "
                     "(an unknown codec or a damaged file)");
  media->current_ = first;
  media->current_index_ = 0;
  media->next_index_ = 1;
  return media;
}

bool ContentMedia::read_next_into(ContentImage& image) {
  cv::Mat frame(image.size.y, image.size.x, CV_8UC3, image.bytes.data());
  const std::uint8_t* before = frame.data;
  if (!video_->capture.read(frame) || frame.empty()) return false;
  if (frame.type() != CV_8UC3 || frame.cols != image.size.x || frame.rows != image.size.y)
    return false;
  // read() writes into the buffer given when the size and type match; copy otherwise.
  if (frame.data != before) {
    cv::Mat into(image.size.y, image.size.x, CV_8UC3, image.bytes.data());
    frame.copyTo(into);
  }
  return true;
}

ContentMedia::Decoded ContentMedia::frame(std::int64_t index) {
  Decoded decoded;
  if (!video_) {
    decoded.image = &first_;
    return decoded;
  }
  index = std::clamp<std::int64_t>(index, 0, frame_count_ - 1);
  decoded.index = index;
  if (index == current_index_) {
    decoded.image = &current_;
    decoded.index = current_index_;
    return decoded;
  }
  const auto start = std::chrono::steady_clock::now();
  cv::VideoCapture& capture = video_->capture;
  if (index < next_index_ || index > next_index_ + kMaxSkip) {
    capture.set(cv::CAP_PROP_POS_FRAMES, double(index));
    next_index_ = index;
    decoded.seeked = true;
  }
  while (next_index_ < index) {
    if (!capture.grab()) break;
    ++next_index_;
    ++decoded.skipped;
  }
  if (next_index_ == index && read_next_into(current_)) {
    current_index_ = index;
    next_index_ = index + 1;
  } else {
    // Past the real end: the file has next_index_ frames. Show the last one.
    frame_count_ = std::max<std::int64_t>(1, std::min(frame_count_, next_index_));
    if (current_index_ != frame_count_ - 1) {
      capture.set(cv::CAP_PROP_POS_FRAMES, double(frame_count_ - 1));
      if (read_next_into(current_)) current_index_ = frame_count_ - 1;
      next_index_ = current_index_ + 1;
      decoded.seeked = true;
    }
  }
  decoded.image = &current_;
  decoded.index = current_index_;
  decoded.decode_ms = ms_since(start);
  return decoded;
}

ContentFormat check_content_format(glm::ivec2 size, std::optional<ContentFormat> requested,
                                   const std::string& source) {
  const bool square = size.x == size.y;
  const bool two_to_one = std::abs(size.x - 2 * size.y) <= 1;
  const bool strip = size.x == 6 * size.y;
  if (!requested) {
    if (square) return ContentFormat::fisheye;
    if (two_to_one) return ContentFormat::equirect;
    if (strip) return ContentFormat::cubemap;
    throw InputError(source, OptionName{"format"},
                     "a square dome master (fisheye), a 2:1 equirectangular panorama or a 6:1 "
                     "cube-map strip; got " +
                         size_text(size) + " (give the format to say which it is)");
  }
  switch (*requested) {
    case ContentFormat::fisheye:
      if (!square)
        throw InputError(source, OptionName{"format"},
                         "a square dome master for fisheye (the circle of the field "
                         "of view inscribed); got " +
                             size_text(size));
      break;
    case ContentFormat::equirect:
      if (!two_to_one)
        throw InputError(source, OptionName{"format"},
                         "an equirectangular panorama twice as wide as high (360° × 180°, to "
                         "the pixel) for equirect; got " +
                             size_text(size));
      break;
    case ContentFormat::cubemap:
      if (!strip)
        throw InputError(source, OptionName{"format"},
                         "a cube map as six square faces side by side (6:1) for cubemap; got " +
                             size_text(size));
      break;
    case ContentFormat::perspective:
      throw InputError(source, OptionName{"format"},
                       "fisheye, equirect or cubemap (a perspective image is per projector, "
                       "for applications)");
  }
  return *requested;
}

}  // namespace facet::driver
