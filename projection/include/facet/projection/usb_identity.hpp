#pragma once
// Who a USB device is, as facet names it in configs and on the command line: the one identity
// type of a camera found through video4linux (calibration/video_camera.hpp) and of a device
// listed through libusb (interop/usb_devices.hpp). Plain values and string functions: no USB
// library, testable without hardware.
#include <cstdint>
#include <string>
#include <vector>

namespace facet {

struct UsbIdentity {
  std::uint16_t vendor_id = 0, product_id = 0;
  std::uint8_t bus = 0;
  std::vector<std::uint8_t> ports;  // port numbers from the root hub down
  std::string serial;               // empty when the device reports none or denies access

  bool operator==(const UsbIdentity&) const = default;
};

// "BUS-P1.P2…", the Linux sysfs name of the port ("BUS-0" for a root hub): stable while the
// cabling stays the same.
std::string bus_path(const UsbIdentity& device);
// "VVVV:PPPP" in lower-case hex.
std::string vid_pid(const UsbIdentity& device);

// The identity a config names a device by: "usb:VVVV:PPPP:SERIAL" when the device reports a
// serial number (it survives re-plugging into another port), else "usb:VVVV:PPPP@BUS-PATH".
std::string stable_id(const UsbIdentity& device);
// What is wrong with `id` as a device id usb:VVVV:PPPP[:SERIAL|@BUS-PATH] (VVVV and PPPP four hex
// digits each, SERIAL printable ASCII, BUS-PATH as bus_path writes it), or "" when nothing is.
std::string stable_id_problem(const std::string& id);
// Whether `id` (a stable_id, or just "usb:VVVV:PPPP" for any such device) names `device`.
bool matches(const std::string& id, const UsbIdentity& device);

}  // namespace facet
