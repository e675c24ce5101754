#include "facet/projection/usb_identity.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace facet {
namespace {

std::string hex4(std::uint16_t value) {
  char text[8];
  std::snprintf(text, sizeof text, "%04x", value);
  return text;
}

}  // namespace

std::string bus_path(const UsbIdentity& device) {
  std::string path = std::to_string(device.bus);
  if (device.ports.empty()) return path + "-0";
  for (std::size_t k = 0; k < device.ports.size(); ++k) {
    path += (k == 0 ? "-" : ".") + std::to_string(device.ports[k]);
  }
  return path;
}

std::string vid_pid(const UsbIdentity& device) {
  return hex4(device.vendor_id) + ":" + hex4(device.product_id);
}

std::string stable_id(const UsbIdentity& device) {
  if (!device.serial.empty()) return "usb:" + vid_pid(device) + ":" + device.serial;
  return "usb:" + vid_pid(device) + "@" + bus_path(device);
}

std::string stable_id_problem(const std::string& id) {
  const std::string expected = "expected usb:VVVV:PPPP[:SERIAL|@BUS-PATH] (see 'facet devices')";
  auto hex4_at = [&](std::size_t at) {
    if (id.size() < at + 4) return false;
    for (std::size_t k = at; k < at + 4; ++k) {
      if (!std::isxdigit(static_cast<unsigned char>(id[k]))) return false;
    }
    return true;
  };
  std::string scheme = id.substr(0, 4);  // "usb:" in any case, as matches takes it
  for (char& c : scheme) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (scheme != "usb:" || !hex4_at(4) || id.size() < 13 || id[8] != ':' || !hex4_at(9)) {
    return expected + ", got '" + id + "'";
  }
  if (id.size() == 13) return "";
  const std::string rest = id.substr(14);
  if (id[13] == ':') {
    const bool printable = !rest.empty() && std::all_of(rest.begin(), rest.end(), [](char c) {
      return c >= 0x20 && c < 0x7f;
    });
    if (!printable) return expected + ": the serial number must be printable ASCII";
    return "";
  }
  if (id[13] == '@') {
    // BUS-P1.P2...: numbers of 1 to 3 digits, the bus then '-', then ports joined by '.'.
    std::size_t digits = 0, numbers = 0;
    bool dash = false, ok = !rest.empty();
    for (const char c : rest) {
      if (std::isdigit(static_cast<unsigned char>(c))) {
        ok = ok && ++digits <= 3;
        continue;
      }
      ok = ok && digits > 0 && (c == '-' ? !dash && numbers == 0 : c == '.' && dash);
      dash = dash || c == '-';
      ++numbers;
      digits = 0;
    }
    if (!ok || !dash || digits == 0) return expected + ": the bus path is BUS-PORT[.PORT...]";
    return "";
  }
  return expected + ", got '" + id + "'";
}

bool matches(const std::string& id, const UsbIdentity& device) {
  const std::string prefix = "usb:" + vid_pid(device);
  std::string lower = id;
  // VID:PID is hex and may be written in capitals; the serial and bus path stay as written.
  for (std::size_t k = 0; k < std::min<std::size_t>(lower.size(), prefix.size()); ++k) {
    lower[k] = char(std::tolower(static_cast<unsigned char>(lower[k])));
  }
  if (lower.compare(0, prefix.size(), prefix) != 0) return false;
  if (lower.size() == prefix.size()) return true;
  return lower == stable_id(device) ||
         (lower[prefix.size()] == '@' && lower.substr(prefix.size() + 1) == bus_path(device));
}

}  // namespace facet
