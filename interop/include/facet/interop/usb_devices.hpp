#pragma once
// USB devices for capture and projector control, through libusb. Enumeration (list_usb_devices,
// UsbWatcher) is kept apart from classification, stable identities and formatting, which are
// plain functions of UsbDevice values and testable without hardware.
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "facet/projection/usb_identity.hpp"

namespace facet::interop {

// A device as libusb lists it: who it is (UsbIdentity: stable_id, matches and bus_path take it as
// one) and what it says of itself.
struct UsbDevice : UsbIdentity {
  std::uint8_t device_class = 0;
  std::vector<std::uint8_t> interface_classes;
  std::string manufacturer, product;  // empty when the device has none or denies access

  bool operator==(const UsbDevice&) const = default;
};

enum class UsbRole { camera, projector_control, other };
const char* to_string(UsbRole role);

// A camera: a video-class (0x0E) interface, or a machine-vision vendor (USB3 Vision devices use a
// vendor-specific class). Projector control: USB–serial adapters (FTDI, Prolific, Silicon Labs,
// WCH) as used for RS-232 projector control, and communications-class (0x02) devices.
UsbRole classify(const UsbDevice& device);

// The identity's functions (facet/projection/usb_identity.hpp), under interop's name too.
using facet::bus_path;
using facet::matches;
using facet::stable_id;
using facet::stable_id_problem;
using facet::vid_pid;

// The devices `id` names; several only for the bare VID:PID form.
std::vector<UsbDevice> find_devices(const std::string& id, const std::vector<UsbDevice>& devices);

// One line per device: VID:PID, role, serial, bus path, stable id, product; or
// "no USB devices" for an empty list.
std::string format_devices(const std::vector<UsbDevice>& devices);

struct UsbListing {
  std::vector<UsbDevice> devices;
  std::string problem;  // non-empty when libusb could not look (no USB subsystem, permissions)
};
// Enumerates the devices now, sorted by bus path.
UsbListing list_usb_devices();

struct UsbChange {
  bool arrived = false;  // false: removed
  UsbDevice device;
};
// What changed from one listing to the next, devices keyed by bus path and VID:PID: removals
// first, then arrivals, each in bus-path order. A device re-plugged into the same port between
// the two listings does not show.
std::vector<UsbChange> diff_devices(const std::vector<UsbDevice>& before,
                                    const std::vector<UsbDevice>& after);
// "+ VID:PID role bus-path stable-id" for an arrival, "- ..." for a removal.
std::string format_change(const UsbChange& change);

enum class UsbWatchMethod { hotplug, polling };
const char* to_string(UsbWatchMethod method);
// hotplug where libusb starts and reports LIBUSB_CAP_HAS_HOTPLUG (Linux with udev or netlink,
// macOS), else polling.
UsbWatchMethod usb_watch_method();

// Follows hotplug until `keep_going()` returns false, calling `on_change` for every arrival and
// removal (diff_devices of the listings before and after). With libusb's hotplug callbacks, an
// event makes it list again and `keep_going` is checked at least every `poll`; without them it
// lists every `poll`. Returns the method it used.
UsbWatchMethod watch_usb_devices(const std::function<void(const UsbChange& change)>& on_change,
                                 const std::function<bool()>& keep_going,
                                 std::chrono::milliseconds poll = std::chrono::milliseconds(500));

}  // namespace facet::interop
