#pragma once
// Content files for playback: still images through OpenImageIO (PNG, JPEG, TIFF: 8-bit sRGB;
// EXR, HDR: linear float) and videos through OpenCV's VideoCapture with its FFmpeg backend (any
// container and codec that FFmpeg decodes), decoded into ContentImages. Non-finite float values
// (NaN, Inf, as some renderers leave in an EXR) show as black.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>

#include "facet/driver/content_pass.hpp"
#include "facet/projection/content_projection.hpp"

namespace facet::driver {

// True for the extensions read as still images: .png .jpg .jpeg .exr .hdr .tif .tiff (any case).
bool is_still_image_path(const std::filesystem::path& path);

class ContentMedia {
 public:
  // Opens `path` and decodes its first frame. InputError naming the file for a missing or
  // non-regular file, an image OpenImageIO cannot read, a video FFmpeg cannot open or whose
  // first frame cannot be decoded (an unknown codec, a damaged file), a frame rate that is not
  // positive, and a size beyond kMaxImageSide / kMaxImagePixels (6 faces for a cube strip).
  static std::unique_ptr<ContentMedia> open(const std::filesystem::path& path);
  ~ContentMedia();

  bool is_video() const { return video_ != nullptr; }
  glm::ivec2 size() const { return first_.size; }
  ContentImage::Pixels pixels() const { return first_.pixels; }
  const std::filesystem::path& path() const { return path_; }
  // Frames a second (0 for a still image).
  double fps() const { return fps_; }
  // Frames in the file: 1 for a still image; for a video what the container says until the end
  // is met (then the frames actually decoded).
  std::int64_t frame_count() const { return frame_count_; }

  struct Decoded {
    const ContentImage* image = nullptr;  // valid until the next call
    std::int64_t index = 0;               // the frame decoded: `index` or, past the end, the last
    std::int64_t skipped = 0;             // frames read past without being decoded to pixels
    bool seeked = false;                  // a seek was needed (backwards, or far ahead)
    double decode_ms = 0;
  };
  // Frame `index` (0-based; clamped to [0, frame_count() − 1]). Reading on from the frame before
  // is cheapest; a frame behind, or more than kMaxSkip ahead, seeks (FFmpeg seeks to the key frame
  // before and decodes forward to the exact frame). A frame past the file's real end updates
  // frame_count() and gives the last frame.
  static constexpr std::int64_t kMaxSkip = 90;
  Decoded frame(std::int64_t index);

 private:
  struct Video;
  ContentMedia() = default;
  bool read_next_into(ContentImage& image);

  std::filesystem::path path_;
  std::unique_ptr<Video> video_;
  double fps_ = 0;
  std::int64_t frame_count_ = 1;
  ContentImage first_;    // frame 0 (a still image's only frame)
  ContentImage current_;  // the last decoded video frame
  std::int64_t current_index_ = 0;
  std::int64_t next_index_ = 1;  // the frame the decoder reads next
};

// The content format an image of `size` is for, checked: `requested`, or from the aspect ratio
// when none is given (square: fisheye, 2:1: equirect, 6:1: cubemap). InputError(source,
// OptionName{"format"}, ...) when the size does not fit: a dome master must be square, an
// equirectangular panorama twice as wide as high (to the pixel), a cube strip six times.
ContentFormat check_content_format(glm::ivec2 size, std::optional<ContentFormat> requested,
                                   const std::string& source);

}  // namespace facet::driver
