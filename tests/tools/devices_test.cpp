// `covtrack devices`: the recognition table and the config snippets as pure functions,
// the listing against a fake /dev + /sys tree, and the real command exiting 0.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <toml++/toml.h>

#include "covtrack/discovery/attached_devices.hpp"
#include "covtrack/discovery/known_devices.hpp"

using namespace covtrack::discovery;
namespace fs = std::filesystem;

TEST(KnownDevices, RecognisesTheSupportedIds) {
  ASSERT_NE(recognise(0x0403, 0x6001), nullptr);
  EXPECT_EQ(recognise(0x0403, 0x6001)->driver_type, "lenz");
  ASSERT_NE(recognise(0x1532, 0x0300), nullptr);
  EXPECT_EQ(recognise(0x1532, 0x0300)->driver_type, "hydra");
  EXPECT_EQ(recognise(0x0f44, 0xff20)->driver_type, "liberty");
  EXPECT_EQ(recognise(0x0f44, 0xff21)->driver_type, "");  // needs its firmware first
  // A vendor-wide row catches other products of a known vendor; the exact row wins.
  EXPECT_EQ(recognise(0x0403, 0x6010)->name, "FTDI USB-serial adapter");
  EXPECT_EQ(recognise(0x0f44, 0x1234)->name, "Polhemus USB device");
  EXPECT_EQ(recognise(0x1532, 0x0001), nullptr);  // another Razer product
  EXPECT_EQ(recognise(0x8086, 0x1234), nullptr);
}

TEST(KnownDevices, EverySnippetIsValidTomlWithTypeAndPath) {
  for (const auto& d : known_devices()) {
    const std::string snippet = config_snippet(d, "/dev/serial/by-id/usb-test-if00");
    toml::table t;
    try {
      t = toml::parse(snippet);
    } catch (const toml::parse_error& e) {
      FAIL() << d.name << ": " << e.what() << "\n" << snippet;
    }
    if (d.driver_type.empty()) {
      EXPECT_TRUE(t.empty()) << "a device that needs a step first gets only a comment";
      continue;
    }
    const auto* dev = t["devices"][d.driver_type].as_table();
    ASSERT_NE(dev, nullptr) << snippet;
    EXPECT_EQ((*dev)["type"].value_or(std::string()), d.driver_type);
    if (d.driver_type == "hydra")
      EXPECT_EQ((*dev)["hid_path"].value_or(std::string()), "/dev/serial/by-id/usb-test-if00");
    else
      EXPECT_EQ((*dev)["port"].value_or(std::string()), "/dev/serial/by-id/usb-test-if00");
  }
  // Without a known path the user is told to check it.
  EXPECT_NE(config_snippet(*recognise(0x0f44, 0xff20), "").find("check the path"), std::string::npos);
}

TEST(AttachedDevices, FindsTtysWithTheirUsbIdsInAFakeTree) {
  const fs::path root = fs::path(::testing::TempDir()) / ("covtrack_devtree_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const fs::path dev = root / "dev", sys = root / "sys";
  fs::create_directories(dev / "serial/by-id");
  std::ofstream(dev / "ttyUSB0").put('x');
  std::ofstream(dev / "ttyS0").put('x');
  std::ofstream(dev / "ttyS1").put('x');
  fs::create_symlink(dev / "ttyUSB0", dev / "serial/by-id/usb-FTDI_FT232R-if00-port0");
  // sysfs: the tty's device sits below the USB device, which has idVendor/idProduct.
  const fs::path usb = sys / "devices/pci0/usb1/1-1";
  fs::create_directories(usb / "1-1:1.0/ttyUSB0");
  std::ofstream(usb / "idVendor") << "0403\n";
  std::ofstream(usb / "idProduct") << "6001\n";
  fs::create_directories(sys / "class/tty/ttyUSB0");
  fs::create_directory_symlink(usb / "1-1:1.0/ttyUSB0", sys / "class/tty/ttyUSB0/device");
  fs::create_directories(sys / "class/tty/ttyS0");
  fs::create_directories(sys / "class/tty/ttyS1");
  std::ofstream(sys / "class/tty/ttyS0/type") << "4\n";  // a 16550A is there
  std::ofstream(sys / "class/tty/ttyS1/type") << "0\n";  // a phantom port

  const auto found = find_attached_devices(dev.string(), sys.string());
  ASSERT_EQ(found.serial.size(), 2u);
  EXPECT_EQ(fs::path(found.serial[0].path).filename(), "ttyS0");
  const auto& usb_tty = found.serial[1];
  EXPECT_EQ(fs::path(usb_tty.path).filename(), "ttyUSB0");
  EXPECT_NE(usb_tty.by_id.find("usb-FTDI_FT232R"), std::string::npos);
  ASSERT_TRUE(usb_tty.vendor_id.has_value());
  EXPECT_EQ(*usb_tty.vendor_id, 0x0403);
  EXPECT_EQ(*usb_tty.product_id, 0x6001);
  fs::remove_all(root);
}

TEST(DevicesCommand, RunsAndExitsZero) {
  const std::string cmd = std::string(COVTRACK_CLI) + " devices > /dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
}
