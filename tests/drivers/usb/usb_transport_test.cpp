// The USB seam without hardware: every UsbError code, the libusb code mappings, the retry wrapper,
// the clocks, handle ownership, and LibusbTransport on a machine that may have no USB at all.
#include <gtest/gtest.h>

#include <sys/types.h>
#include <array>
#include <climits>
#include <cstdint>
#include <set>
#include <string>
#include <utility>

#include "drivers/usb/libusb_call.hpp"
#include "drivers/usb/libusb_transport.hpp"

namespace drv = orthoflow::drivers;
using Code = drv::UsbError::Code;
using drv::UsbPacketStatus;
using namespace std::chrono_literals;

namespace {

template <class T>
using R = orthoflow::Result<T, drv::UsbError>;
using Handle = const drv::UsbDeviceHandle&;
using Bytes = std::span<std::byte>;

// A second, minimal implementation of the seam: it needs no libusb, and it counts closes.
class CountingTransport final : public drv::UsbTransport {
 public:
  int closes = 0;
  std::uint32_t last_closed = 0;

  R<std::vector<drv::UsbDeviceInfo>> enumerate(std::uint16_t,
                                               std::optional<std::uint16_t>) override {
    return std::vector<drv::UsbDeviceInfo>{};
  }
  R<drv::UsbDeviceHandle> open(const drv::UsbDeviceInfo&) override {
    return make_handle(next_id_++);
  }
  R<void> claim_interface(Handle, std::uint8_t) override { return no(); }
  R<void> release_interface(Handle, std::uint8_t) override { return no(); }
  R<void> set_alt_setting(Handle, std::uint8_t, std::uint8_t) override { return no(); }
  R<bool> kernel_driver_active(Handle, std::uint8_t) override { return no(); }
  R<void> detach_kernel_driver(Handle, std::uint8_t) override { return no(); }
  R<void> attach_kernel_driver(Handle, std::uint8_t) override { return no(); }
  R<void> reset_device(Handle) override { return no(); }
  R<void> clear_halt(Handle, std::uint8_t) override { return no(); }
  R<std::size_t> control(Handle, const drv::UsbControlSetup&, Bytes, drv::UsbTimeout) override {
    return no();
  }
  R<std::size_t> bulk(Handle, std::uint8_t, Bytes, drv::UsbTimeout) override { return no(); }
  R<std::size_t> interrupt(Handle, std::uint8_t, Bytes, drv::UsbTimeout) override { return no(); }
  R<std::size_t> max_iso_packet_size(Handle, std::uint8_t) override { return no(); }
  R<void> start_iso(Handle, std::uint8_t, const drv::UsbIsoConfig&, drv::UsbIsoCallback) override {
    return no();
  }
  R<void> stop_iso(Handle, std::uint8_t) override { return no(); }
  R<drv::UsbIsoStats> iso_stats(Handle, std::uint8_t) const override { return no(); }
  R<void> handle_events(drv::UsbTimeout) override { return {}; }
  const drv::MonotonicClock& clock() const noexcept override { return clock_; }

 private:
  static orthoflow::Unexpected<drv::UsbError> no() {
    return orthoflow::err(drv::refused(Code::NOT_SUPPORTED, "x"));
  }
  void close_device(std::uint32_t id) noexcept override {
    ++closes;
    last_closed = id;
  }
  drv::ManualClock clock_;
  std::uint32_t next_id_ = 1;
};

drv::UsbDeviceInfo device_at(std::uint8_t bus, std::initializer_list<std::uint8_t> ports) {
  drv::UsbDeviceInfo info;
  info.bus = bus;
  for (std::uint8_t port : ports) info.port_path[info.port_depth++] = port;
  return info;
}

template <class T>
Code code_of(const R<T>& result) {
  return result ? Code::OTHER : result.error().code;  // OTHER is never what a test here expects
}

std::size_t bytes_of(const R<std::size_t>& result) { return result ? *result : SIZE_MAX; }

}  // namespace

TEST(UsbError, EveryCodeHasItsOwnNameAndMessage) {
  std::set<std::string> names;
  for (std::size_t i = 0; i < drv::USB_ERROR_CODE_COUNT; ++i) {
    const std::string name = drv::to_string(static_cast<Code>(i));
    EXPECT_NE(name, "unknown") << "code " << i << " has no name";
    EXPECT_TRUE(names.insert(name).second) << "duplicate name " << name;
  }
  EXPECT_STREQ(drv::to_string(static_cast<Code>(drv::USB_ERROR_CODE_COUNT)), "unknown");
  EXPECT_STREQ(drv::to_string(Code::SHORT_TRANSFER), "short_transfer");
  // The message names the code, the operation and the native code.
  EXPECT_EQ(drv::to_string(drv::UsbError{Code::NO_DEVICE, -4, "libusb_open"}),
            "no_device in libusb_open (native -4)");
  EXPECT_EQ(drv::to_string(drv::UsbError{}), "other in (unnamed call) (native 0)");
}

TEST(LibusbCodes, EveryLibusbErrorMapsToItsOwnCode) {
  // libusb.h's documented LIBUSB_ERROR_* values, IO = -1 ... NOT_SUPPORTED = -12, OTHER = -99.
  const std::array<std::pair<int, Code>, 13> table{{{-1, Code::IO},
                                                    {-2, Code::INVALID_PARAM},
                                                    {-3, Code::ACCESS},
                                                    {-4, Code::NO_DEVICE},
                                                    {-5, Code::NOT_FOUND},
                                                    {-6, Code::BUSY},
                                                    {-7, Code::TIMEOUT},
                                                    {-8, Code::OVERFLOW},
                                                    {-9, Code::PIPE},
                                                    {-10, Code::INTERRUPTED},
                                                    {-11, Code::NO_MEM},
                                                    {-12, Code::NOT_SUPPORTED},
                                                    {-99, Code::OTHER}}};
  std::set<Code> seen;
  for (const auto& [native, code] : table) {
    EXPECT_EQ(drv::usb_error_code_from_libusb(native), code) << "native " << native;
    seen.insert(code);
  }
  EXPECT_EQ(seen.size(), table.size()) << "two libusb errors share a code";
  for (int unknown : {-13, -98, -100, INT_MIN, 0, 1}) {
    EXPECT_EQ(drv::usb_error_code_from_libusb(unknown), Code::OTHER) << "native " << unknown;
  }
}

TEST(LibusbCodes, EveryTransferStatusMapsToItsOwnPacketStatus) {
  // libusb_transfer_status: COMPLETED 0, ERROR 1, TIMED_OUT 2, CANCELLED 3, STALL 4, NO_DEVICE 5,
  // OVERFLOW 6.
  const std::array<UsbPacketStatus, 7> expected{
      UsbPacketStatus::COMPLETED, UsbPacketStatus::ERROR, UsbPacketStatus::TIMED_OUT,
      UsbPacketStatus::CANCELLED, UsbPacketStatus::STALL, UsbPacketStatus::NO_DEVICE,
      UsbPacketStatus::OVERFLOW};
  std::set<std::string> names;
  for (int native = 0; native < 7; ++native) {
    EXPECT_EQ(drv::usb_packet_status_from_libusb(native),
              expected[static_cast<std::size_t>(native)]);
    EXPECT_TRUE(names.insert(drv::to_string(expected[static_cast<std::size_t>(native)])).second);
  }
  EXPECT_EQ(drv::usb_packet_status_from_libusb(7), UsbPacketStatus::ERROR);
  EXPECT_EQ(drv::usb_packet_status_from_libusb(-1), UsbPacketStatus::ERROR);
  EXPECT_STREQ(drv::to_string(static_cast<UsbPacketStatus>(200)), "unknown");
}

TEST(LibusbCall, RetriesInterruptedCallsThenReturnsTheValue) {
  int calls = 0;
  auto value_result = drv::libusb_call(
      "libusb_x", [&] { return ++calls < 3 ? drv::LIBUSB_INTERRUPTED_NATIVE : 42; });
  ASSERT_TRUE(value_result);
  EXPECT_EQ(*value_result, 42);
  EXPECT_EQ(calls, 3);
  auto count_result = drv::libusb_call("libusb_get_device_list",
                                       [] { return ssize_t{0}; });  // ssize_t, as libusb's
  ASSERT_TRUE(count_result);
  EXPECT_EQ(*count_result, 0);
}

TEST(LibusbCall, GivesUpAfterBoundedRetries) {
  int calls = 0;
  auto result =
      drv::libusb_call("libusb_open", [&] { return ++calls, drv::LIBUSB_INTERRUPTED_NATIVE; });
  EXPECT_EQ(code_of(result), Code::INTERRUPTED);
  EXPECT_EQ(calls, drv::LIBUSB_CALL_MAX_ATTEMPTS);
  EXPECT_EQ(result.error().native, drv::LIBUSB_INTERRUPTED_NATIVE);
}

TEST(LibusbCall, MapsOtherErrorsWithoutRetrying) {
  int calls = 0;
  auto result = drv::libusb_call("libusb_claim_interface", [&] { return ++calls, -6; });
  EXPECT_EQ(code_of(result), Code::BUSY);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(result.error().native, -6);
  EXPECT_EQ(result.error().operation, "libusb_claim_interface");
}

TEST(FinishTransfer, ShortInIsDataShortOutIsAnErrorAndLengthsAreClamped) {
  EXPECT_EQ(bytes_of(drv::finish_transfer(0, 12, 64, false, "libusb_interrupt_transfer")), 12u);
  EXPECT_EQ(bytes_of(drv::finish_transfer(0, 64, 64, true, "libusb_interrupt_transfer")), 64u);
  auto short_result = drv::finish_transfer(0, 20, 64, true, "libusb_bulk_transfer");
  EXPECT_EQ(code_of(short_result), Code::SHORT_TRANSFER);
  EXPECT_EQ(short_result.error().native, 20) << "native carries the bytes moved";
  EXPECT_EQ(code_of(drv::finish_transfer(-7, 30, 64, true, "libusb_bulk_transfer")), Code::TIMEOUT);
  EXPECT_EQ(code_of(drv::finish_transfer(-9, 0, 64, false, "libusb_bulk_transfer")), Code::PIPE);
  // Impossible lengths are distrusted, never passed on.
  EXPECT_EQ(bytes_of(drv::finish_transfer(0, 1000, 64, false, "libusb_bulk_transfer")), 64u);
  EXPECT_EQ(code_of(drv::finish_transfer(0, -5, 8, true, "libusb_bulk_transfer")),
            Code::SHORT_TRANSFER);
}

TEST(Clocks, ManualClockMovesOnlyWhenTold) {
  drv::ManualClock clock(1'000);
  EXPECT_EQ(clock.now_ns(), 1'000);
  clock.advance(5ms);
  EXPECT_EQ(clock.now_ns(), 1'000 + 5'000'000);
  clock.set_ns(clock.now_ns());  // standing still is allowed
  clock.set_ns(9'000'000'000);
  const drv::MonotonicClock& as_interface = clock;
  EXPECT_EQ(as_interface.now_ns(), 9'000'000'000);
}

TEST(ClocksDeathTest, ManualClockNeverGoesBack) {
  drv::ManualClock clock(100);
  EXPECT_DEATH(clock.advance(-1ns), "backwards");
  EXPECT_DEATH(clock.set_ns(99), "backwards");
}

TEST(Clocks, SteadyClockNeverDecreases) {
  const drv::SteadyClock clock;
  std::int64_t previous = clock.now_ns();
  for (int i = 0; i < 1000; ++i) {
    const std::int64_t now = clock.now_ns();
    EXPECT_GE(now, previous);
    previous = now;
  }
}

TEST(UsbDeviceInfo, PortsAndParentHub) {
  const auto camera = device_at(1, {2, 1});
  const auto motor = device_at(1, {2, 3});
  EXPECT_EQ(camera.ports().size(), 2u);
  EXPECT_EQ(camera.ports()[1], 1);
  EXPECT_TRUE(drv::same_parent_hub(camera, motor));
  EXPECT_FALSE(drv::same_parent_hub(camera, device_at(2, {2, 3}))) << "other bus";
  EXPECT_FALSE(drv::same_parent_hub(camera, device_at(1, {3, 3}))) << "other hub";
  EXPECT_FALSE(drv::same_parent_hub(camera, device_at(1, {2, 1, 4}))) << "other depth";
  EXPECT_FALSE(drv::same_parent_hub(device_at(1, {}), device_at(1, {})))
      << "unknown paths never match";
  EXPECT_TRUE(camera.serial.view().empty());
}

TEST(UsbDeviceHandle, ClosesOnceAndMovesOwnership) {
  CountingTransport transport;
  EXPECT_FALSE(drv::UsbDeviceHandle{}.is_open());
  {
    auto first_result = transport.open({});
    ASSERT_TRUE(first_result);
    drv::UsbDeviceHandle first = std::move(*first_result);
    EXPECT_TRUE(first.is_open());
    EXPECT_EQ(first.transport(), &transport);
    drv::UsbDeviceHandle moved(std::move(first));
    EXPECT_FALSE(
        first.is_open());  // NOLINT(bugprone-use-after-move): the moved-from state is the point
    EXPECT_EQ(transport.closes, 0);
    auto second_result = transport.open({});
    ASSERT_TRUE(second_result);
    moved = std::move(*second_result);  // closes device 1
    EXPECT_EQ(transport.closes, 1);
    EXPECT_EQ(transport.last_closed, 1u);
    transport.close(moved);
    EXPECT_FALSE(moved.is_open());
    EXPECT_EQ(transport.last_closed, 2u);
    transport.close(moved);  // empty: no-op
  }
  EXPECT_EQ(transport.closes, 2) << "destructors of closed or moved-from handles close nothing";
}

TEST(LibusbTransport, CreateGivesATransportOrANamedError) {
  auto transport_result = drv::LibusbTransport::create();
  if (!transport_result) {
    // libusb could not start here: the error must say so cleanly.
    EXPECT_STRNE(drv::to_string(transport_result.error().code), "unknown");
    EXPECT_EQ(transport_result.error().operation, "libusb_init");
    GTEST_SKIP() << "libusb_init failed: " << drv::to_string(transport_result.error());
  }
  drv::LibusbTransport& transport = **transport_result;
  for (const auto& product :
       {std::optional<std::uint16_t>{0x02AE}, std::optional<std::uint16_t>{}}) {
    auto devices_result =
        transport.enumerate(0x045E, product);  // Kinect camera, then any Microsoft device
    ASSERT_TRUE(devices_result) << drv::to_string(devices_result.error());
    for (const auto& device : *devices_result) {
      EXPECT_EQ(device.vendor, 0x045E);
      EXPECT_LE(device.port_depth, drv::USB_MAX_PORT_DEPTH);
    }
  }
  EXPECT_TRUE(transport.enumerate(0x22CD, std::nullopt));  // JACO: vendor only
  EXPECT_TRUE(transport.handle_events(0ms));
  EXPECT_EQ(code_of(transport.handle_events(-1ms)), Code::INVALID_PARAM);
  EXPECT_GT(transport.clock().now_ns(), 0);
}

TEST(LibusbTransport, OpeningAnAbsentDeviceFails) {
  auto transport_result = drv::LibusbTransport::create();
  if (!transport_result) GTEST_SKIP() << drv::to_string(transport_result.error());
  drv::UsbDeviceInfo absent = device_at(255, {7, 7, 7});
  absent.address = 255;  // addresses stop at 127
  absent.vendor = 0x045E;
  absent.product = 0x02AE;
  auto open_result = (*transport_result)->open(absent);
  const Code code = code_of(open_result);
  EXPECT_TRUE(code == Code::NO_DEVICE || code == Code::NOT_FOUND) << drv::to_string(code);
}

TEST(LibusbTransport, EveryDeviceCallRefusesAHandleItDidNotOpen) {
  drv::ManualClock clock(7);
  auto transport_result = drv::LibusbTransport::create(clock);
  if (!transport_result) GTEST_SKIP() << drv::to_string(transport_result.error());
  drv::LibusbTransport& transport = **transport_result;
  EXPECT_EQ(&transport.clock(), &clock);
  CountingTransport other;
  auto foreign_result = other.open({});
  ASSERT_TRUE(foreign_result);
  const drv::UsbDeviceHandle empty;
  std::array<std::byte, 8> buffer{};
  const drv::UsbDeviceHandle& foreign_ref = *foreign_result;
  for (const drv::UsbDeviceHandle* handle : {&empty, &foreign_ref}) {
    EXPECT_EQ(code_of(transport.claim_interface(*handle, 0)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.release_interface(*handle, 0)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.set_alt_setting(*handle, 0, 1)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.kernel_driver_active(*handle, 0)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.detach_kernel_driver(*handle, 0)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.attach_kernel_driver(*handle, 0)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.reset_device(*handle)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.clear_halt(*handle, 0x81)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.control(*handle, {0xC0, 0, 0, 0}, buffer, 500ms)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.bulk(*handle, 0x81, buffer, 500ms)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.interrupt(*handle, 0x82, buffer, 500ms)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.max_iso_packet_size(*handle, 0x82)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.start_iso(*handle, 0x82, {}, [](auto, auto, auto) {})),
              Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.stop_iso(*handle, 0x82)), Code::NOT_OPEN);
    EXPECT_EQ(code_of(transport.iso_stats(*handle, 0x82)), Code::NOT_OPEN);
  }
  drv::UsbDeviceHandle foreign = std::move(*foreign_result);
  transport.close(foreign);  // not this transport's: left alone
  EXPECT_TRUE(foreign.is_open());
}
