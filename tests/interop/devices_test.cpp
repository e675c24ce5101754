#include <gtest/gtest.h>

#include "facet/interop/usb_devices.hpp"

namespace facet::interop {
namespace {

UsbDevice camera() {
  UsbDevice d;
  d.vendor_id = 0x046d;
  d.product_id = 0x085c;
  d.bus = 3;
  d.ports = {2, 1};
  d.interface_classes = {0x0e, 0x0e, 0x01};
  d.serial = "A1B2C3";
  d.product = "C922 Pro Stream Webcam";
  return d;
}

UsbDevice serial_adapter() {
  UsbDevice d;
  d.vendor_id = 0x0403;
  d.product_id = 0x6001;
  d.bus = 1;
  d.ports = {4};
  d.interface_classes = {0xff};
  return d;
}

TEST(UsbDevices, RolesFromClassAndVendor) {
  EXPECT_EQ(classify(camera()), UsbRole::camera);
  EXPECT_EQ(classify(serial_adapter()), UsbRole::projector_control);
  UsbDevice vision;
  vision.vendor_id = 0x2676;  // Basler, USB3 Vision with a vendor-specific class
  vision.interface_classes = {0xef};
  EXPECT_EQ(classify(vision), UsbRole::camera);
  UsbDevice hub;
  hub.vendor_id = 0x1d6b;
  hub.device_class = 0x09;
  EXPECT_EQ(classify(hub), UsbRole::other);
}

TEST(UsbDevices, StableIdentityPrefersTheSerialAndFallsBackToThePort) {
  EXPECT_EQ(bus_path(camera()), "3-2.1");
  EXPECT_EQ(stable_id(camera()), "usb:046d:085c:A1B2C3");
  EXPECT_EQ(stable_id(serial_adapter()), "usb:0403:6001@1-4");
  // The serial identity survives moving the camera to another port; the port identity does not.
  UsbDevice moved = camera();
  moved.ports = {5};
  EXPECT_TRUE(matches(stable_id(camera()), moved));
  UsbDevice moved_adapter = serial_adapter();
  moved_adapter.ports = {3};
  EXPECT_FALSE(matches(stable_id(serial_adapter()), moved_adapter));
  EXPECT_TRUE(matches("USB:046D:085C", camera()));
  EXPECT_FALSE(matches("usb:046d:085c:OTHER", camera()));
  EXPECT_FALSE(matches("usb:046d:085d", camera()));
  const std::vector<UsbDevice> all{camera(), serial_adapter(), moved};
  EXPECT_EQ(find_devices("usb:046d:085c", all).size(), 2u);
  EXPECT_EQ(find_devices("usb:0403:6001@1-4", all).size(), 1u);
}

// The forms an id may take; anything else is refused with what was expected (the CLI's --find and
// --camera usb:... say so with exit status 2 instead of finding nothing or the wrong device).
TEST(UsbDevices, StableIdSyntax) {
  for (const char* good : {"usb:046d:085c", "USB:046D:085C", "usb:046d:085c:A1B2C3",
                           "usb:0403:6001@1-4", "usb:0403:6001@1-4.2.1", "usb:0403:6001@3-0"}) {
    EXPECT_EQ(stable_id_problem(good), "") << good;
  }
  for (const char* bad : {"",
                          "usb:",
                          "usb::",
                          "usb:046d",
                          "usb:046d:",
                          "usb:zzzz:0000",
                          "usb:12345:0000",
                          "usb:1234:56789",
                          "usb:-1:1",
                          "pci:1234:5678",
                          "usb:1234:5678@",
                          "usb:1234:5678:",
                          "usb:1234:5678:\xff",
                          "usb:1234:5678:a\nb",
                          "usb:1234:5678@1",
                          "usb:1234:5678@1-",
                          "usb:1234:5678@-1",
                          "usb:1234:5678@1-2..3",
                          "usb:1234:5678@1-2-3",
                          "usb:1234:5678@1234-1",
                          "usb:0x12:0x34",
                          "usb:1234:5678#1-1"}) {
    EXPECT_NE(stable_id_problem(bad), "") << bad;
  }
  EXPECT_TRUE(matches(stable_id(camera()), camera()));
  EXPECT_EQ(stable_id_problem(stable_id(camera())), "");
  EXPECT_EQ(stable_id_problem(stable_id(serial_adapter())), "");
}

TEST(UsbDevices, Formatting) {
  EXPECT_EQ(format_devices({}), "no USB devices\n");
  const std::string table = format_devices({camera(), serial_adapter()});
  EXPECT_NE(table.find("046d:085c"), std::string::npos);
  EXPECT_NE(table.find("camera"), std::string::npos);
  EXPECT_NE(table.find("projector-control"), std::string::npos);
  EXPECT_NE(table.find("usb:0403:6001@1-4"), std::string::npos);
}

TEST(UsbDevices, WatchReportsRemovalsThenArrivalsFromTwoListings) {
  // A camera moves to another port, the serial adapter leaves, a second camera arrives.
  UsbDevice moved = camera();
  moved.ports = {5};
  UsbDevice second = camera();
  second.serial = "ZZ";
  second.ports = {2, 3};
  const std::vector<UsbChange> changes =
      diff_devices({camera(), serial_adapter()}, {moved, second, camera()});
  ASSERT_EQ(changes.size(), 3u);
  EXPECT_FALSE(changes[0].arrived);
  EXPECT_EQ(changes[0].device, serial_adapter());
  EXPECT_TRUE(changes[1].arrived);
  EXPECT_EQ(changes[1].device, second);  // bus 3, ports 2.3 sort before 5
  EXPECT_TRUE(changes[2].arrived);
  EXPECT_EQ(changes[2].device, moved);
  EXPECT_EQ(format_change(changes[0]), "- 0403:6001 projector-control 1-4 usb:0403:6001@1-4");
  EXPECT_EQ(format_change(changes[1]), "+ 046d:085c camera 3-2.3 usb:046d:085c:ZZ");
  // Same devices, any order: nothing to report.
  EXPECT_TRUE(diff_devices({camera(), serial_adapter()}, {serial_adapter(), camera()}).empty());
  EXPECT_TRUE(diff_devices({}, {}).empty());
  EXPECT_EQ(diff_devices({}, {camera()}).size(), 1u);
}

TEST(UsbDevices, WatchStopsWhenAsked) {
  // Whichever method this machine has, the watch returns once keep_going says so and reports
  // nothing when nothing changes (no device is expected to come or go during the test).
  int calls = 0, changes = 0;
  const UsbWatchMethod method =
      watch_usb_devices([&](const UsbChange&) { ++changes; }, [&] { return ++calls <= 3; },
                        std::chrono::milliseconds(20));
  EXPECT_EQ(method, usb_watch_method());
  EXPECT_EQ(calls, 4);
  EXPECT_EQ(changes, 0);
}

TEST(UsbDevices, ListingRunsWhereverItIs) {
  // No USB devices may exist here; the call must return either way.
  const UsbListing listing = list_usb_devices();
  for (const UsbDevice& device : listing.devices) EXPECT_FALSE(bus_path(device).empty());
}

}  // namespace
}  // namespace facet::interop
