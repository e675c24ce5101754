#include "facet/interop/usb_devices.hpp"

#include <libusb.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <set>
#include <thread>
#include <tuple>

namespace facet::interop {
namespace {

std::string descriptor_string(libusb_device_handle* handle, std::uint8_t index) {
  if (!handle || index == 0) return {};
  unsigned char text[256];
  const int length = libusb_get_string_descriptor_ascii(handle, index, text, sizeof text);
  if (length <= 0) return {};
  std::string result(reinterpret_cast<const char*>(text), std::size_t(length));
  // Serials go into configs and tables: keep them printable.
  for (char& c : result) {
    if (c < 0x21 || c > 0x7e) c = '_';
  }
  return result;
}

UsbDevice describe(libusb_device* device) {
  UsbDevice result;
  libusb_device_descriptor descriptor{};
  if (libusb_get_device_descriptor(device, &descriptor) != 0) return result;
  result.vendor_id = descriptor.idVendor;
  result.product_id = descriptor.idProduct;
  result.device_class = descriptor.bDeviceClass;
  result.bus = libusb_get_bus_number(device);
  std::uint8_t ports[8];
  const int depth = libusb_get_port_numbers(device, ports, 8);
  for (int k = 0; k < depth; ++k) result.ports.push_back(ports[k]);
  libusb_config_descriptor* config = nullptr;
  if (libusb_get_active_config_descriptor(device, &config) == 0 && config) {
    for (int i = 0; i < config->bNumInterfaces; ++i) {
      for (int a = 0; a < config->interface[i].num_altsetting; ++a) {
        result.interface_classes.push_back(config->interface[i].altsetting[a].bInterfaceClass);
      }
    }
    libusb_free_config_descriptor(config);
  }
  // Strings need the device opened, which permissions may deny: then they stay empty.
  libusb_device_handle* handle = nullptr;
  if (libusb_open(device, &handle) == 0) {
    result.serial = descriptor_string(handle, descriptor.iSerialNumber);
    result.manufacturer = descriptor_string(handle, descriptor.iManufacturer);
    result.product = descriptor_string(handle, descriptor.iProduct);
    libusb_close(handle);
  }
  return result;
}

void sort_devices(std::vector<UsbDevice>& devices) {
  std::sort(devices.begin(), devices.end(), [](const UsbDevice& a, const UsbDevice& b) {
    return std::tie(a.bus, a.ports, a.vendor_id, a.product_id) <
           std::tie(b.bus, b.ports, b.vendor_id, b.product_id);
  });
}

}  // namespace

const char* to_string(UsbRole role) {
  switch (role) {
    case UsbRole::camera:
      return "camera";
    case UsbRole::projector_control:
      return "projector-control";
    case UsbRole::other:
      break;
  }
  return "other";
}

UsbRole classify(const UsbDevice& device) {
  constexpr std::uint8_t kVideo = 0x0e, kCommunications = 0x02;
  const auto has_class = [&](std::uint8_t c) {
    return device.device_class == c ||
           std::find(device.interface_classes.begin(), device.interface_classes.end(), c) !=
               device.interface_classes.end();
  };
  if (has_class(kVideo)) return UsbRole::camera;
  // Machine-vision cameras (USB3 Vision uses a vendor-specific class): FLIR/Point Grey, Basler,
  // IDS, Allied Vision, XIMEA, The Imaging Source.
  static const std::set<std::uint16_t> camera_vendors{0x1e10, 0x2676, 0x1409,
                                                      0x1ab2, 0x20f7, 0x199e};
  if (camera_vendors.count(device.vendor_id)) return UsbRole::camera;
  // USB–serial bridges that drive projectors' RS-232 control ports: FTDI, Prolific,
  // Silicon Labs, WCH.
  static const std::set<std::uint16_t> serial_vendors{0x0403, 0x067b, 0x10c4, 0x1a86};
  if (serial_vendors.count(device.vendor_id) || has_class(kCommunications)) {
    return UsbRole::projector_control;
  }
  return UsbRole::other;
}

std::vector<UsbDevice> find_devices(const std::string& id, const std::vector<UsbDevice>& devices) {
  std::vector<UsbDevice> found;
  for (const UsbDevice& device : devices) {
    if (matches(id, device)) found.push_back(device);
  }
  return found;
}

std::string format_devices(const std::vector<UsbDevice>& devices) {
  if (devices.empty()) return "no USB devices\n";
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-10s %-18s %-12s %-20s %-32s %s\n", "VID:PID", "role",
                "bus path", "serial", "stable id", "product");
  out += line;
  for (const UsbDevice& device : devices) {
    const std::string product =
        device.manufacturer.empty() ? device.product : device.manufacturer + " " + device.product;
    std::snprintf(line, sizeof line, "%-10s %-18s %-12s %-20s %-32s %s\n", vid_pid(device).c_str(),
                  to_string(classify(device)), bus_path(device).c_str(),
                  device.serial.empty() ? "-" : device.serial.c_str(), stable_id(device).c_str(),
                  product.empty() ? "-" : product.c_str());
    out += line;
  }
  return out;
}

UsbListing list_usb_devices() {
  UsbListing listing;
  libusb_context* context = nullptr;
  if (const int code = libusb_init(&context); code != 0) {
    listing.problem = std::string("libusb cannot start: ") + libusb_strerror(code);
    return listing;
  }
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(context, &list);
  if (count < 0) {
    listing.problem = std::string("libusb cannot list devices: ") + libusb_strerror(int(count));
  } else {
    for (ssize_t k = 0; k < count; ++k) listing.devices.push_back(describe(list[k]));
    libusb_free_device_list(list, 1);
  }
  libusb_exit(context);
  sort_devices(listing.devices);
  return listing;
}

std::vector<UsbChange> diff_devices(const std::vector<UsbDevice>& before,
                                    const std::vector<UsbDevice>& after) {
  const auto key = [](const UsbDevice& d) { return std::make_tuple(d.bus, d.ports, vid_pid(d)); };
  std::map<decltype(key(UsbDevice{})), const UsbDevice*> old_devices, new_devices;
  for (const UsbDevice& device : before) old_devices[key(device)] = &device;
  for (const UsbDevice& device : after) new_devices[key(device)] = &device;
  std::vector<UsbChange> changes;
  for (const auto& [k, device] : old_devices) {
    if (!new_devices.count(k)) changes.push_back({false, *device});
  }
  for (const auto& [k, device] : new_devices) {
    if (!old_devices.count(k)) changes.push_back({true, *device});
  }
  return changes;
}

std::string format_change(const UsbChange& change) {
  return std::string(change.arrived ? "+ " : "- ") + vid_pid(change.device) + " " +
         to_string(classify(change.device)) + " " + bus_path(change.device) + " " +
         stable_id(change.device);
}

const char* to_string(UsbWatchMethod method) {
  return method == UsbWatchMethod::hotplug ? "libusb hotplug events" : "polling";
}

UsbWatchMethod usb_watch_method() {
  libusb_context* context = nullptr;
  if (libusb_init(&context) != 0) return UsbWatchMethod::polling;
  const bool hotplug = libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) != 0;
  libusb_exit(context);
  return hotplug ? UsbWatchMethod::hotplug : UsbWatchMethod::polling;
}

namespace {

int LIBUSB_CALL on_hotplug(libusb_context*, libusb_device*, libusb_hotplug_event, void* flag) {
  // Device descriptors may not be opened inside the callback: note the event, list afterwards.
  *static_cast<bool*>(flag) = true;
  return 0;  // stay registered
}

}  // namespace

UsbWatchMethod watch_usb_devices(const std::function<void(const UsbChange& change)>& on_change,
                                 const std::function<bool()>& keep_going,
                                 std::chrono::milliseconds poll) {
  std::vector<UsbDevice> known = list_usb_devices().devices;
  const auto relist = [&] {
    std::vector<UsbDevice> now = list_usb_devices().devices;
    for (const UsbChange& change : diff_devices(known, now)) on_change(change);
    known = std::move(now);
  };
  libusb_context* context = nullptr;
  libusb_hotplug_callback_handle handle = 0;
  bool event = false;
  const bool hotplug =
      libusb_init(&context) == 0 && libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) &&
      libusb_hotplug_register_callback(context,
                                       libusb_hotplug_event(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                                            LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
                                       libusb_hotplug_flag(0), LIBUSB_HOTPLUG_MATCH_ANY,
                                       LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY,
                                       on_hotplug, &event, &handle) == LIBUSB_SUCCESS;
  if (!hotplug) {
    if (context) libusb_exit(context);
    while (keep_going()) {
      std::this_thread::sleep_for(poll);
      relist();
    }
    return UsbWatchMethod::polling;
  }
  const auto seconds = std::chrono::duration_cast<std::chrono::microseconds>(poll).count();
  while (keep_going()) {
    timeval timeout{static_cast<decltype(timeval::tv_sec)>(seconds / 1000000),
                    static_cast<decltype(timeval::tv_usec)>(seconds % 1000000)};
    libusb_handle_events_timeout_completed(context, &timeout, nullptr);
    if (event) {
      event = false;
      relist();
    }
  }
  libusb_hotplug_deregister_callback(context, handle);
  libusb_exit(context);
  return UsbWatchMethod::hotplug;
}

}  // namespace facet::interop
