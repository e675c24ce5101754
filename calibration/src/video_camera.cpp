#include "facet/calibration/video_camera.hpp"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "facet/projection/errors.hpp"

namespace facet::calibration {
namespace {

namespace fs = std::filesystem;

std::string read_attribute(const fs::path& path) {
  std::ifstream stream(path);
  std::string value;
  std::getline(stream, value);
  while (!value.empty() && (value.back() == '\n' || value.back() == ' ' || value.back() == '\r')) {
    value.pop_back();
  }
  return value;
}

std::optional<int> parse_int(const std::string& text, int base = 10) {
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value, base);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

// Fills the USB fields from the first directory at or above `start` that has idVendor.
void read_usb_identity(const fs::path& start, VideoDevice& device) {
  std::error_code error;
  fs::path directory = fs::canonical(start, error);
  if (error) return;
  for (int depth = 0; depth < 4 && !directory.empty(); ++depth) {
    if (fs::exists(directory / "idVendor", error)) {
      const auto vendor = parse_int(read_attribute(directory / "idVendor"), 16);
      const auto product = parse_int(read_attribute(directory / "idProduct"), 16);
      const auto bus = parse_int(read_attribute(directory / "busnum"));
      if (!vendor || !product || !bus) return;
      UsbIdentity usb;
      usb.vendor_id = std::uint16_t(*vendor);
      usb.product_id = std::uint16_t(*product);
      usb.bus = std::uint8_t(*bus);
      usb.serial = read_attribute(directory / "serial");
      // devpath is "2" or "2.3.1": the ports from the root hub down.
      const std::string devpath = read_attribute(directory / "devpath");
      std::size_t begin = 0;
      while (begin <= devpath.size() && !devpath.empty()) {
        const std::size_t end = std::min(devpath.find('.', begin), devpath.size());
        if (const auto port = parse_int(devpath.substr(begin, end - begin))) {
          usb.ports.push_back(std::uint8_t(*port));
        }
        begin = end + 1;
      }
      device.usb = std::move(usb);
      return;
    }
    directory = directory.parent_path();
  }
}

class VideoCaptureCamera : public LiveCamera {
 public:
  VideoCaptureCamera(const std::string& device, std::string identity,
                     const VideoCameraOptions& options)
      : device_(device), identity_(std::move(identity)), discard_(options.discard) {
    if (discard_ < 0) throw InputError(OptionName{"discard"}, "a number of frames >= 0");
    const auto index = parse_int(device);
    if (index) {
      capture_.open(*index, cv::CAP_V4L2);
    } else {
      std::error_code error;
      if (!fs::exists(device, error)) {
        throw InputError(OptionName{"device"},
                         "a camera device: '" + device +
                             "' does not exist (give /dev/videoN, an index, a usb: stable id "
                             "from 'facet devices', or fake:RIG.json)");
      }
      capture_.open(device, cv::CAP_V4L2);
    }
    if (!capture_.isOpened()) {
      throw InputError(OptionName{"device"}, "a V4L2 camera that opens, but '" + device +
                                                 "' does not (busy or not a "
                                                 "capture device?)");
    }
    capture_.set(cv::CAP_PROP_BUFFERSIZE, 1);
    if (options.size) {
      capture_.set(cv::CAP_PROP_FRAME_WIDTH, options.size->x);
      capture_.set(cv::CAP_PROP_FRAME_HEIGHT, options.size->y);
    }
    const cv::Mat first = read_grey();
    size_ = {first.cols, first.rows};
    if (options.size && size_ != *options.size) {
      throw InputError(OptionName{"size"},
                       std::to_string(options.size->x) + "x" + std::to_string(options.size->y) +
                           ", a size '" + device + "' offers; it delivers " +
                           std::to_string(size_.x) + "x" + std::to_string(size_.y));
    }
  }

  glm::ivec2 size() const override { return size_; }

  cv::Mat grab(const GrabKey&) override {
    for (int k = 0; k < discard_; ++k) capture_.grab();
    cv::Mat frame = read_grey();
    if (frame.cols != size_.x || frame.rows != size_.y) {
      throw InputError(OptionName{"device"}, "frames of one size from '" + device_ + "'");
    }
    return frame;
  }

  nlohmann::json identity() const override {
    return {{"device", identity_}, {"size", {size_.x, size_.y}}};
  }

 private:
  cv::Mat read_grey() {
    cv::Mat frame;
    if (!capture_.read(frame) || frame.empty()) {
      throw InputError(OptionName{"device"},
                       "frames from '" + device_ + "', but reading one failed");
    }
    cv::Mat grey;
    if (frame.channels() == 3) {
      cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    } else if (frame.channels() == 4) {
      cv::cvtColor(frame, grey, cv::COLOR_BGRA2GRAY);
    } else {
      grey = frame;
    }
    cv::Mat scaled;
    const double full = grey.depth() == CV_16U ? 65535.0 : grey.depth() == CV_8U ? 255.0 : 1.0;
    grey.convertTo(scaled, CV_32F, 1.0 / full);
    return scaled;
  }

  std::string device_, identity_;
  int discard_ = 2;
  cv::VideoCapture capture_;
  glm::ivec2 size_{0, 0};
};

}  // namespace

std::vector<VideoDevice> list_video_devices(const fs::path& sysfs_root, const fs::path& dev_root) {
  std::vector<VideoDevice> devices;
  const fs::path class_dir = sysfs_root / "class" / "video4linux";
  std::error_code error;
  if (!fs::is_directory(class_dir, error)) return devices;
  for (const auto& entry : fs::directory_iterator(class_dir, error)) {
    VideoDevice device;
    const std::string node = entry.path().filename().string();
    device.node = dev_root / node;
    device.name = read_attribute(entry.path() / "name");
    device.index = parse_int(read_attribute(entry.path() / "index")).value_or(0);
    read_usb_identity(entry.path() / "device", device);
    devices.push_back(std::move(device));
  }
  std::sort(devices.begin(), devices.end(), [](const VideoDevice& a, const VideoDevice& b) {
    return a.node.string() < b.node.string();
  });
  return devices;
}

std::unique_ptr<LiveCamera> open_video_camera(const std::string& device,
                                              const std::string& identity,
                                              const VideoCameraOptions& options) {
  return std::make_unique<VideoCaptureCamera>(device, identity, options);
}

std::string find_video_node(const std::string& camera, const std::vector<VideoDevice>& devices) {
  if (!camera.starts_with("usb:")) return camera;
  if (const std::string problem = stable_id_problem(camera); !problem.empty()) {
    throw InputError(OptionName{"device"}, problem);
  }
  std::vector<std::string> matched;
  std::string seen;
  for (const VideoDevice& device : devices) {
    if (!device.usb || device.index != 0) continue;
    seen += (seen.empty() ? "" : ", ") + device.node.string() + " = " + stable_id(*device.usb);
    if (matches(camera, *device.usb)) matched.push_back(device.node.string());
  }
  if (matched.size() == 1) return matched.front();
  if (matched.empty()) {
    throw InputError(OptionName{"device"},
                     "a connected USB camera with the id " + camera +
                         " (video devices: " + (seen.empty() ? "none" : seen) + ")");
  }
  std::string list;
  for (const std::string& node : matched) list += (list.empty() ? "" : ", ") + node;
  throw InputError(OptionName{"device"}, "an id that names one camera, but " + camera + " names " +
                                             list + ": add the serial number or bus path");
}

}  // namespace facet::calibration
