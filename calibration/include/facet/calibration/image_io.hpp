#pragma once
// Image files for captures and patterns, through OpenImageIO.
#include <filesystem>
#include <glm/glm.hpp>
#include <opencv2/core.hpp>
#include <string>

namespace facet::calibration {

struct ImageInfo {
  glm::ivec2 size{0, 0};  // width, height in pixels
  int channels = 0;
  std::string format;  // OpenImageIO's name for the file format, e.g. "png", "openexr"
};

// Reads only the header. Throws InputError naming `path` when the file is missing, not a regular
// file or unreadable, when its OpenEXR header asks for more than the file holds
// (projection_io::check_exr_header), or when its size is beyond kMaxImageSide / kMaxImagePixels or
// more pixels than its bytes can encode; read_luminance checks the same before allocating.
ImageInfo read_image_info(const std::filesystem::path& path);

// Reads an 8- or 16-bit PNG or an EXR (any format OpenImageIO reads) as CV_32F luminance:
// integer formats are scaled to [0,1] (no colour-space conversion: capture images are linear in
// light), grey is taken as is and RGB(A) becomes Rec. 709 luminance 0.2126 R + 0.7152 G +
// 0.0722 B; alpha is ignored and never multiplied in. Throws InputError when unreadable.
cv::Mat read_luminance(const std::filesystem::path& path);

// Writes a single-channel CV_32F image of values in [0,1] (clamped) as an 8- or 16-bit grey PNG,
// rounding to the nearest level, or as a float EXR when the extension is .exr; bit_depth is then
// ignored. Writes to a temporary file and renames it. Asserts on a bad Mat or bit depth; throws
// InputError when the file cannot be written.
void write_grey_image(const std::filesystem::path& path, const cv::Mat& image, int bit_depth = 8);

// Writes a CV_8UC3 image, channels in R, G, B order, as an 8-bit RGB PNG (or any format the
// extension names), through a temporary file renamed onto `path`. InputError when it cannot.
void write_rgb_image(const std::filesystem::path& path, const cv::Mat& rgb);

}  // namespace facet::calibration
