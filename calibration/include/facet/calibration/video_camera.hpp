#pragma once
// Real cameras for live capture: V4L2/UVC devices through OpenCV's VideoCapture, and the lookup of
// a device's /dev/videoN node from sysfs so that configs can name a USB camera by its stable
// identity (`usb:VVVV:PPPP:SERIAL` or `usb:VVVV:PPPP@BUS-PATH`, projection/usb_identity.hpp).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "facet/calibration/live_capture.hpp"
#include "facet/projection/usb_identity.hpp"

namespace facet::calibration {

// A video4linux capture node and, for USB devices, the USB device it belongs to.
struct VideoDevice {
  std::filesystem::path node;      // e.g. /dev/video0
  std::string name;                // the driver's name for the node (sysfs `name`)
  int index = 0;                   // sysfs `index`: 0 is a device's main capture node
  std::optional<UsbIdentity> usb;  // set for the nodes of a USB device
};

// The video4linux nodes under `sysfs_root`/class/video4linux, sorted by node name, with their USB
// identity read from the USB device directory above each node's `device` link (idVendor,
// idProduct, serial, busnum, devpath). Nodes are named `dev_root`/<node>. Empty when sysfs has
// no video4linux class (no cameras, or no sysfs).
std::vector<VideoDevice> list_video_devices(const std::filesystem::path& sysfs_root = "/sys",
                                            const std::filesystem::path& dev_root = "/dev");

// The device node `camera` names among `devices`: a USB stable id (usb:VVVV:PPPP[:SERIAL|@BUS-
// PATH]) is matched against the USB devices' main capture nodes (index 0); anything else (a node,
// an index) is returned as it is. Throws InputError(OptionName "device", ...) for a malformed id,
// an id that matches no device (listing the ids there are) or one that matches several.
std::string find_video_node(const std::string& camera, const std::vector<VideoDevice>& devices);

struct VideoCameraOptions {
  std::optional<glm::ivec2> size;  // ask the driver for this frame size (W, H)
  // Frames read and dropped before each grab, so that no frame buffered while the previous
  // pattern was shown is used.
  int discard = 2;
};

// A camera opened through OpenCV VideoCapture with the V4L2 backend: `device` is a device node
// (/dev/videoN) or an index ("0"). `identity` names it in the capture journal (the stable USB id
// when the config gave one, else the node). Frames become grey (BT.601 luma of colour frames),
// scaled so that full scale is 1. Throws InputError(OptionName "device", ...) when the device does
// not open or delivers no frame, and when a grab later fails.
std::unique_ptr<LiveCamera> open_video_camera(const std::string& device,
                                              const std::string& identity,
                                              const VideoCameraOptions& options = {});

}  // namespace facet::calibration
